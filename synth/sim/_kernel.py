"""The compiled simulation loop (numba), shared by the closed and the open loop.

One call simulates a batch of variants, padded to common sizes. Per step
``k`` (time ``k dt``):

1. plant core output at ``k dt`` (before this step's input takes effect):
   ``y = C x + Dw w_{k-m-1} + Dd d_k``; row 0 is the true output, row 1 the
   output of the sensor dynamics folded into the core;
2. sensor chain -> measured output;
3. controller (every ``ratio`` steps; held in between): ``e = r - y_meas``,
   ``v = Cc xc + Dc e``; in the open loop the command is the given input;
4. actuator chain on ``u0 + v`` -> actuator output ``a``;
5. ``w_k = a - u0`` enters the delay buffer; the core state advances with
   ``w_{k-m-1}``, ``w_{k-m}`` (exact fractional delay) and the disturbances.

Block activity is recorded as bits of an int32 per step: bit ``i`` for
actuator block ``i``, bit ``SENSOR_BIT + i`` (16 + i) for sensor block ``i``
(:mod:`synth.sim.layout`).
"""

from __future__ import annotations

import numpy as np

from synth.jit import jit
from synth.sim._steps import block_step
from synth.sim.layout import NOISE, SENSOR_BIT


@jit
def run_loop(mode, A, B_early, B_late, Bd, C, Dw, Dd, steps,
             Ac, Bc, Cc, Dc, Aaw, Baw, aw_tap, ratio,
             u0, y0, ys_off,
             act_codes, act_p, act_s0, act_noise, sen_codes, sen_p, sen_s0, sen_noise,
             ref, d_in, d_out,
             x0, xc0, w0, v0,
             Y, YM, U, UA, FLAGS):
    """Simulate every variant ``b`` of the batch; outputs are written into ``Y, YM, U, UA, FLAGS``.

    ``mode`` 0 is the closed loop; 1 the open loop, where ``ref`` holds the absolute input.
    """
    nb = A.shape[0]
    n = A.shape[1]
    nc = Ac.shape[1]
    na = act_codes.shape[1]
    ns = sen_codes.shape[1]
    n_steps = Y.shape[1]
    length = 2
    for b in range(nb):
        if steps[b] + 2 > length:
            length = steps[b] + 2
    buf = np.empty(length)
    x = np.empty(n)
    xn = np.empty(n)
    xc = np.empty(nc)
    xcn = np.empty(nc)
    for b in range(nb):
        rb = b if ref.shape[0] > 1 else 0
        db = b if d_in.shape[0] > 1 else 0
        anb = b if act_noise.shape[0] > 1 else 0
        snb = b if sen_noise.shape[0] > 1 else 0
        m = steps[b]
        for i in range(length):
            buf[i] = w0[b]
        for i in range(n):
            x[i] = x0[b, i]
        for i in range(nc):
            xc[i] = xc0[b, i]
        act_s = act_s0[b].copy()
        sen_s = sen_s0[b].copy()
        v = v0[b]
        e = 0.0
        for k in range(n_steps):
            w_prev = buf[(k - m - 1 + length) % length]
            din = d_in[db, k]
            dout = d_out[db, k]
            yt = Dw[b, 0] * w_prev + Dd[b, 0, 0] * din + Dd[b, 0, 1] * dout
            ys = Dw[b, 1] * w_prev + Dd[b, 1, 0] * din + Dd[b, 1, 1] * dout
            for i in range(n):
                yt += C[b, 0, i] * x[i]
                ys += C[b, 1, i] * x[i]
            flags = 0
            val = ys_off[b] + ys
            for i in range(ns):
                code = sen_codes[b, i]
                if code == NOISE:
                    val = val + sen_noise[snb, int(sen_p[b, i, 0]), k]
                else:
                    val, active = block_step(code, sen_p[b, i], sen_s[i], val, k)
                    if active:
                        flags |= 1 << (SENSOR_BIT + i)
            ym = val
            update = False
            if mode == 0:
                if k % ratio[b] == 0:
                    e = ref[rb, k] - ym
                    v = Dc[b] * e
                    for i in range(nc):
                        v += Cc[b, i] * xc[i]
                    update = True
                cmd = u0[b] + v
            else:
                cmd = ref[rb, k]
            val = cmd
            tap = cmd
            for i in range(na):
                code = act_codes[b, i]
                if code == NOISE:
                    val = val + act_noise[anb, int(act_p[b, i, 0]), k]
                else:
                    val, active = block_step(code, act_p[b, i], act_s[i], val, k)
                    if active:
                        flags |= 1 << i
                if i == aw_tap[b]:
                    tap = val
            a = val
            if update and nc > 0:
                if aw_tap[b] >= 0:
                    for i in range(nc):
                        acc = Baw[b, i] * (tap - u0[b])
                        for j in range(nc):
                            acc += Aaw[b, i, j] * xc[j]
                        xcn[i] = acc
                else:
                    for i in range(nc):
                        acc = Bc[b, i] * e
                        for j in range(nc):
                            acc += Ac[b, i, j] * xc[j]
                        xcn[i] = acc
                for i in range(nc):
                    xc[i] = xcn[i]
            buf[k % length] = a - u0[b]
            w_cur = buf[(k - m + length) % length]
            for i in range(n):
                acc = B_early[b, i] * w_prev + B_late[b, i] * w_cur + Bd[b, i, 0] * din + Bd[b, i, 1] * dout
                for j in range(n):
                    acc += A[b, i, j] * x[j]
                xn[i] = acc
            for i in range(n):
                x[i] = xn[i]
            Y[b, k] = y0[b] + yt
            YM[b, k] = ym
            U[b, k] = cmd
            UA[b, k] = a
            FLAGS[b, k] = flags
    return 0
