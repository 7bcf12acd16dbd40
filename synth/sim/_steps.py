"""Per-step block equations (numba), dispatched on each block's integer code.

Parameter and state layouts are those of :mod:`synth.sim.layout`, written by the block
classes of :mod:`synth.sim.blocks`; each function updates the state in place and returns
``(output, active)``.
"""

from __future__ import annotations

import numpy as np

from synth.jit import jit
from synth.sim.layout import (
    BACKLASH,
    DEAD_ZONE,
    DYNAMICS,
    MAX_TABLE,
    NOISE,
    QUANTIZER,
    RATE_LIMIT,
    SAMPLE_HOLD,
    SATURATION,
    STATIC,
    SUPPLY_SAG,
)


@jit
def rate_limit_step(p, s, x):
    """Rate limiter: ``p = [R dt, F dt]``, ``s = [y_prev]``; returns ``(y, limited)``."""
    d = x - s[0]
    if d > p[0]:
        y, active = s[0] + p[0], True
    elif d < -p[1]:
        y, active = s[0] - p[1], True
    else:
        y, active = x, False
    s[0] = y
    return y, active


@jit
def saturation_step(p, x):
    """Saturation: ``p = [min, max]``."""
    if x > p[1]:
        return p[1], True
    if x < p[0]:
        return p[0], True
    return x, False


@jit
def dead_zone_step(p, x):
    """Dead zone: ``p = [center, half_width]``; active inside the zone."""
    d = x - p[0]
    if d > p[1]:
        return x - p[1], False
    if d < -p[1]:
        return x + p[1], False
    return p[0], True


@jit
def quantizer_step(p, x):
    """Quantizer: ``p = [step, offset, mode]`` (mode 0 rounds to nearest, 1 floors)."""
    if p[0] <= 0.0:
        return x, False
    v = (x - p[1]) / p[0]
    if p[2] == 0.0:
        n = np.floor(v + 0.5)
    else:
        n = np.floor(v)
    return p[1] + p[0] * n, False


@jit
def backlash_step(p, s, x):
    """Backlash (play): ``p = [half_width]``, ``s = [y_prev]``; active while the output rests."""
    y = s[0]
    if x - p[0] > y:
        y, active = x - p[0], False
    elif x + p[0] < y:
        y, active = x + p[0], False
    else:
        active = True
    s[0] = y
    return y, active


@jit
def static_step(p, x):
    """Piecewise-linear table: ``p = [n, x_1..x_n (padded to 16), y_1..y_n]``, ends extrapolated."""
    n = int(p[0])
    xs = p[1:1 + n]
    ys = p[1 + MAX_TABLE:1 + MAX_TABLE + n]
    if n == 1:
        return ys[0], False
    i = 0
    while i < n - 2 and x > xs[i + 1]:
        i += 1
    # the fraction of the segment, then the rise: exact at a symmetric segment's middle (a relay's table gives 0
    # at 0, where the slope form gave 5.6e-17, which a steep relay amplified into chatter while the loop was at rest)
    return ys[i] + (x - xs[i]) / (xs[i + 1] - xs[i]) * (ys[i + 1] - ys[i]), False


@jit
def dynamics_step(p, s, x):
    """Discrete state space of order ``n <= 4``: ``p = [n, A (4x4), B (4), C (4), D]``."""
    n = int(p[0])
    y = p[25] * x
    for i in range(n):
        y += p[21 + i] * s[i]
    for i in range(n):
        acc = p[17 + i] * x
        for j in range(n):
            acc += p[1 + 4 * i + j] * s[j]
        s[4 + i] = acc
    for i in range(n):
        s[i] = s[4 + i]
    return y, False


@jit
def supply_sag_step(p, s, x):
    """Battery sag and brown-out: ``p = [V_oc, V_n, R_i, i_s, i_d, a, V_reset, reset_steps, u_off]``,
    ``s = [x_filtered, reset_steps_left]``; active during a brown-out reset."""
    current = p[3] * x + p[4] * (x - s[0])
    if current < 0.0:
        current = 0.0
    volts = p[0] - p[2] * current
    s[0] = p[5] * s[0] + (1.0 - p[5]) * x
    if s[1] > 0.0:
        s[1] -= 1.0
        return p[8], True
    if volts < p[6]:
        s[1] = p[7] - 1.0
        return p[8], True
    return x * volts / p[1], False


@jit
def sample_hold_step(p, s, x, k):
    """Sample-and-hold: ``p = [period_steps, first_sample_step]``, ``s = [held, next_sample_step]``."""
    if k + 1e-9 >= s[1]:
        s[0] = x
        while s[1] <= k + 1e-9:
            s[1] += p[0]
    return s[0], False


@jit(inline="always")
def block_step(code, p, s, x, k):
    """Apply block ``code`` with parameters ``p`` and state ``s`` (updated in place) at step ``k``.

    Returns ``(y, active)``; ``active`` flags a limiting block that acted this step
    (rate limit or saturation clipping, dead zone or backlash resting, brown-out).
    Noise blocks are applied by the kernel, which owns the noise samples.
    """
    if code == RATE_LIMIT:
        return rate_limit_step(p, s, x)
    if code == SATURATION:
        return saturation_step(p, x)
    if code == DEAD_ZONE:
        return dead_zone_step(p, x)
    if code == QUANTIZER:
        return quantizer_step(p, x)
    if code == DYNAMICS:
        return dynamics_step(p, s, x)
    if code == SUPPLY_SAG:
        return supply_sag_step(p, s, x)
    if code == SAMPLE_HOLD:
        return sample_hold_step(p, s, x, k)
    if code == BACKLASH:
        return backlash_step(p, s, x)
    if code == STATIC:
        return static_step(p, x)
    return x, False


@jit
def run_chain(codes, params, state, noise, x, flags):
    """Run a chain over the signal ``x``; activity flags go into ``flags[block, step]``."""
    n = x.shape[0]
    y = np.empty(n)
    for k in range(n):
        v = x[k]
        for i in range(codes.shape[0]):
            if codes[i] == NOISE:
                v = v + noise[int(params[i, 0]), k]
            else:
                v, active = block_step(codes[i], params[i], state[i], v, k)
                if active:
                    flags[i, k] = True
        y[k] = v
    return y
