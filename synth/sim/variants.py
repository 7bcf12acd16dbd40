"""From loop descriptions to the kernel: each variant compiled to arrays, padded into one batch,
run by one call of the compiled loop (``synth.sim._kernel.run_loop``).

:func:`run_variants` is the one place the kernel is called; the public entry points are in
:mod:`synth.sim.simulator`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, is_dataclass
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.sim._kernel import run_loop
from synth.sim.blocks import Block, ChainArrays, Delay, chain_arrays
from synth.sim.discretize import delayed_zoh, discretize_controller, zoh
from synth.sim.folding import fold_counts, plant_core
from synth.sim.layout import P_MAX, S_MAX
from synth.sim.results import BatchResult
from synth.sim.signals import Reference

__all__ = ["run_variants"]


@dataclass
class _Compiled:
    """One variant as kernel arrays (unpadded)."""

    A: np.ndarray
    B_early: np.ndarray
    B_late: np.ndarray
    Bd: np.ndarray
    C: np.ndarray
    Dw: np.ndarray
    Dd: np.ndarray
    steps: int
    Ac: np.ndarray
    Bc: np.ndarray
    Cc: np.ndarray
    Dc: float
    Aaw: np.ndarray
    Baw: np.ndarray
    aw_tap: int
    ratio: int
    u0: float
    y0: float
    ys_off: float
    act: ChainArrays
    sen: ChainArrays
    ref: np.ndarray
    d_in: np.ndarray
    d_out: np.ndarray
    x0: np.ndarray
    xc0: np.ndarray
    w0: float
    v0: float


def _disturbance_arrays(disturbances: Sequence[Any], t: np.ndarray, rng: np.random.Generator,
                        n_pre: int) -> tuple[np.ndarray, np.ndarray]:
    d_in = np.zeros(t.size)
    d_out = np.zeros(t.size)
    t_main = t[n_pre:]
    for d in disturbances:
        sig = np.asarray(d.signal(t_main, rng), float)
        if sig.shape != t_main.shape or not np.all(np.isfinite(sig)):
            raise ModelError(f"disturbance {d!r} did not give one finite value per step")
        (d_in if d.at == "input" else d_out)[n_pre:] += sig
    return d_in, d_out


def _reference_array(reference: Reference, t: np.ndarray, n_pre: int) -> tuple[np.ndarray, float]:
    t_main = t[n_pre:]
    if callable(reference):
        r = np.asarray(reference(t_main), float)
    else:
        r = np.asarray(reference, float)
        if r.ndim == 0:
            r = np.full(t_main.size, float(r))
    if r.shape != t_main.shape:
        raise ModelError(f"reference has {r.size} samples; the simulation has {t_main.size} "
                         f"(0 to {t_main[-1]:g} s every {t[1] - t[0]:g} s)")
    if not np.all(np.isfinite(r)):
        raise ModelError("reference has non-finite values")
    rest = float(getattr(reference, "initial", r[0]))
    return np.concatenate([np.full(n_pre, rest), r]), rest


_PLANTS: dict[tuple[Any, ...], tuple[Any, Any, np.ndarray]] = {}
"""Discretized plant cores already built in this process (a gain sweep changes only the controller)."""


def _discrete_plant(plant: Any, act_f: list[Block], sen_f: list[Block], op: Any, dt: float,
                    delay: float) -> tuple[Any, Any, np.ndarray]:
    """The plant core with the folded blocks, its zero-order hold with the loop delay and the disturbance
    inputs' hold: built once per plant, folded blocks (dataclasses: their repr is their value), operating
    point, sample time and delay. The arrays are shared between the variants that use them; nothing
    writes into them."""
    key = (plant.num.tobytes(), plant.den.tobytes(), repr(act_f), repr(sen_f), repr(op), dt, delay)
    cacheable = all(is_dataclass(b) for b in (*act_f, *sen_f)) and is_dataclass(op)
    if cacheable and key in _PLANTS:
        return _PLANTS[key]
    core = plant_core(plant, act_f, sen_f, op)
    dz = delayed_zoh(core.A, core.B[:, 0], dt, delay)
    _, Bd = zoh(core.A, core.B[:, 1:], dt)
    if cacheable:
        if len(_PLANTS) >= 64:
            _PLANTS.clear()
        _PLANTS[key] = (core, dz, Bd)
    return core, dz, Bd


def _compile(loop: Any, mode: int, ref: np.ndarray, rest: float, d_in: np.ndarray, d_out: np.ndarray,
             rng: np.random.Generator) -> _Compiled:
    dt = loop.dt
    op = loop.operating_point
    act = [b for b in loop.actuator if not isinstance(b, Delay)]
    sen = [b for b in loop.sensor if not isinstance(b, Delay)]
    na_fold, ns_fold = fold_counts(act, sen)
    act_x, act_f = act[: len(act) - na_fold], act[len(act) - na_fold:]
    sen_f, sen_x = sen[:ns_fold], sen[ns_fold:]
    core, dz, Bd = _discrete_plant(loop.plant, act_f, sen_f, op, dt, loop.total_delay)
    n = core.A.shape[0]
    d_in = d_in + core.input_offset

    # controller
    if mode == 0:
        ratio = loop.controller_ratio
        num, den = loop.controller.tf()
        Ac, Bc, Cc, Dc = discretize_controller(num, den, ratio * dt, loop.discretization)
    else:
        ratio = 1
        Ac, Bc, Cc, Dc = np.zeros((0, 0)), np.zeros(0), np.zeros(0), 0.0
    nc = Ac.shape[0]
    aw_tap = -1
    Aaw, Baw = np.zeros((nc, nc)), np.zeros(nc)
    if mode == 0 and loop.anti_windup:
        aw_tap = _anti_windup_tap(act_x)
        if nc:
            if abs(Dc) < 1e-12:
                raise ModelError(f"anti_windup needs a controller with a direct term; {loop.controller} has none")
            Aaw = Ac - np.outer(Bc, Cc) / Dc
            Baw = Bc / Dc
            if np.max(np.abs(np.linalg.eigvals(Aaw))) >= 1.0:
                raise ModelError(f"anti_windup needs a controller with stable zeros; {loop.controller} has not")
        else:
            aw_tap = -1

    # steady state at rest (nonlinear blocks as identity)
    ga = float(np.prod([b.dc_gain() for b in act_x])) if act_x else 1.0
    gs = float(np.prod([b.dc_gain() for b in sen_x])) if sen_x else 1.0
    d0 = np.array([d_in[0], d_out[0]])
    Bw = dz.B_early + dz.B_late
    if mode == 0:
        size = n + nc + 3
        M = np.zeros((size, size))
        rhs = np.zeros(size)
        iv, iw, ie = n + nc, n + nc + 1, n + nc + 2
        M[:n, :n] = np.eye(n) - dz.Ad
        M[:n, iw] = -Bw
        rhs[:n] = Bd @ d0
        M[n:n + nc, n:n + nc] = np.eye(nc) - Ac
        M[n:n + nc, ie] = -Bc
        M[iv, iv] = 1.0
        M[iv, n:n + nc] = -Cc
        M[iv, ie] = -Dc
        M[iw, iw] = 1.0
        M[iw, iv] = -ga
        rhs[iw] = ga * op.input - op.input
        M[ie, ie] = 1.0
        M[ie, :n] = gs * core.C[1]
        M[ie, iw] = gs * core.D[1, 0]
        rhs[ie] = rest - gs * (core.sensed_offset + core.D[1, 1:] @ d0)
        z = np.linalg.lstsq(M, rhs, rcond=None)[0]
        x0, xc0, v0, w0 = z[:n], z[n:n + nc], float(z[iv]), float(z[iw])
        command0 = op.input + v0
    else:
        w0 = ga * rest - op.input
        x0 = np.linalg.lstsq(np.eye(n) - dz.Ad, Bw * w0 + Bd @ d0, rcond=None)[0] if n else np.zeros(0)
        xc0, v0 = np.zeros(0), 0.0
        command0 = rest
    y_sensed0 = core.sensed_offset + (core.C[1] @ x0 if n else 0.0) + core.D[1, 0] * w0 + core.D[1, 1:] @ d0
    n_steps = ref.size
    act_arr = chain_arrays(act_x, dt, command0, op.input, n_steps, rng)
    sen_arr = chain_arrays(sen_x, dt, float(y_sensed0), op.input, n_steps, rng)
    return _Compiled(dz.Ad, dz.B_early, dz.B_late, Bd, core.C, core.D[:, 0], core.D[:, 1:], dz.steps,
                     Ac, Bc, Cc, Dc, Aaw, Baw, aw_tap, ratio, op.input, op.output, core.sensed_offset,
                     act_arr, sen_arr, ref, d_in, d_out, x0, xc0, w0, v0)


def _anti_windup_tap(act: list[Block]) -> int:
    tap = -1
    for i, b in enumerate(act):
        if not b.command_side:
            break
        tap = i
    if tap < 0:
        raise ModelError("anti_windup needs the actuator chain to start with a rate_limit, saturation or "
                         "quantizer block (the limits the controller knows about)")
    return tap


def _stack(items: list[_Compiled]) -> dict[str, np.ndarray]:
    nb = len(items)
    n = max(1, max(c.A.shape[0] for c in items))
    nc = max(1, max(c.Ac.shape[0] for c in items))
    na = max(1, max(c.act.codes.size for c in items))
    ns = max(1, max(c.sen.codes.size for c in items))
    n_steps = items[0].ref.size
    out = {
        "A": np.zeros((nb, n, n)), "B_early": np.zeros((nb, n)), "B_late": np.zeros((nb, n)),
        "Bd": np.zeros((nb, n, 2)), "C": np.zeros((nb, 2, n)), "Dw": np.zeros((nb, 2)), "Dd": np.zeros((nb, 2, 2)),
        "steps": np.zeros(nb, np.int64), "Ac": np.zeros((nb, nc, nc)), "Bc": np.zeros((nb, nc)),
        "Cc": np.zeros((nb, nc)), "Dc": np.zeros(nb), "Aaw": np.zeros((nb, nc, nc)), "Baw": np.zeros((nb, nc)),
        "aw_tap": np.zeros(nb, np.int64), "ratio": np.ones(nb, np.int64), "u0": np.zeros(nb),
        "y0": np.zeros(nb), "ys_off": np.zeros(nb),
        "act_codes": np.zeros((nb, na), np.int64), "act_p": np.zeros((nb, na, P_MAX)),
        "act_s0": np.zeros((nb, na, S_MAX)),
        "sen_codes": np.zeros((nb, ns), np.int64), "sen_p": np.zeros((nb, ns, P_MAX)),
        "sen_s0": np.zeros((nb, ns, S_MAX)),
        "ref": np.zeros((nb, n_steps)), "d_in": np.zeros((nb, n_steps)), "d_out": np.zeros((nb, n_steps)),
        "x0": np.zeros((nb, n)), "xc0": np.zeros((nb, nc)), "w0": np.zeros(nb), "v0": np.zeros(nb),
    }
    n_act_noise = max(c.act.noise.shape[0] for c in items)
    n_sen_noise = max(c.sen.noise.shape[0] for c in items)
    out["act_noise"] = np.zeros((nb, n_act_noise, n_steps))
    out["sen_noise"] = np.zeros((nb, n_sen_noise, n_steps))
    for b, c in enumerate(items):
        k, kc = c.A.shape[0], c.Ac.shape[0]
        out["A"][b, :k, :k] = c.A
        out["B_early"][b, :k] = c.B_early
        out["B_late"][b, :k] = c.B_late
        out["Bd"][b, :k] = c.Bd
        out["C"][b, :, :k] = c.C
        out["Dw"][b] = c.Dw
        out["Dd"][b] = c.Dd
        out["steps"][b] = c.steps
        out["Ac"][b, :kc, :kc] = c.Ac
        out["Bc"][b, :kc] = c.Bc
        out["Cc"][b, :kc] = c.Cc
        out["Dc"][b] = c.Dc
        out["Aaw"][b, :kc, :kc] = c.Aaw
        out["Baw"][b, :kc] = c.Baw
        out["aw_tap"][b] = c.aw_tap
        out["ratio"][b] = c.ratio
        out["u0"][b], out["y0"][b], out["ys_off"][b] = c.u0, c.y0, c.ys_off
        for pre, arr in (("act", c.act), ("sen", c.sen)):
            m = arr.codes.size
            out[f"{pre}_codes"][b, :m] = arr.codes
            out[f"{pre}_p"][b, :m] = arr.params
            out[f"{pre}_s0"][b, :m] = arr.state
            out[f"{pre}_noise"][b, : arr.noise.shape[0]] = arr.noise[:, :n_steps]
        out["ref"][b], out["d_in"][b], out["d_out"][b] = c.ref, c.d_in, c.d_out
        out["x0"][b, :k] = c.x0
        out["xc0"][b, :kc] = c.xc0
        out["w0"][b], out["v0"][b] = c.w0, c.v0
    return out


def run_variants(loops: Sequence[Any], mode: int, inputs: Sequence[Any], t_end: float, disturbances: Sequence[Any],
                 seed: int, settle: float) -> BatchResult:
    """Simulate every variant of ``loops`` from 0 to ``t_end`` seconds in one kernel call.

    Parameters
    ----------
    loops : sequence of NonlinearLoop or OpenLoop
        The variants (same ``dt``).
    mode : int
        0 for the closed loop (``inputs`` are references), 1 for the open loop (``inputs`` are
        absolute input records).
    inputs : sequence
        One reference or input record per variant (see :data:`synth.sim.signals.Reference`).
    t_end : float
        Simulated time (s).
    disturbances : sequence
        Disturbance objects of :mod:`synth.sim.signals`.
    seed : int
        Variant ``b`` draws its random signals with the seed ``[seed, b]``.
    settle : float
        Seconds simulated before ``t = 0`` at the initial reference and dropped.

    Returns
    -------
    BatchResult

    Examples
    --------
    >>> from synth.controllers import Controller
    >>> from synth.plant import Plant
    >>> from synth.sim.loops import NonlinearLoop
    >>> loop = NonlinearLoop(Plant.from_string("10/(s+10)"), Controller("P", {"kp": 4}))
    >>> round(float(run_variants([loop], 0, [1.0], 1.0, (), 0, 0.0).output[0, -1]), 3)
    0.8
    """
    if not loops:
        raise ModelError("no variants to simulate")
    dt = loops[0].dt
    if any(abs(lp.dt - dt) > 1e-15 * dt for lp in loops):
        raise ModelError("every variant of a batch needs the same dt")
    if not (np.isfinite(t_end) and t_end > 0):
        raise ModelError(f"the simulated time must be > 0 s, got {t_end!r}")
    if settle < 0:
        raise ModelError(f"settle must be >= 0 s, got {settle!r}")
    n_main = round(t_end / dt) + 1
    n_pre = round(settle / dt)
    t = (np.arange(n_pre + n_main) - n_pre) * dt
    items = []
    for b, (loop, ref) in enumerate(zip(loops, inputs)):
        rng = np.random.default_rng([seed, b])
        r, rest = _reference_array(ref, t, n_pre)
        d_in, d_out = _disturbance_arrays(disturbances, t, rng, n_pre)
        items.append(_compile(loop, mode, r, rest, d_in, d_out, rng))
    arrays = _stack(items)
    nb, n_steps = len(items), t.size
    Y, YM, U, UA = (np.empty((nb, n_steps)) for _ in range(4))
    FLAGS = np.zeros((nb, n_steps), np.int32)
    run_loop(mode, arrays["A"], arrays["B_early"], arrays["B_late"], arrays["Bd"], arrays["C"], arrays["Dw"],
             arrays["Dd"], arrays["steps"], arrays["Ac"], arrays["Bc"], arrays["Cc"], arrays["Dc"], arrays["Aaw"],
             arrays["Baw"], arrays["aw_tap"], arrays["ratio"], arrays["u0"], arrays["y0"], arrays["ys_off"],
             arrays["act_codes"], arrays["act_p"], arrays["act_s0"], arrays["act_noise"], arrays["sen_codes"],
             arrays["sen_p"], arrays["sen_s0"], arrays["sen_noise"], arrays["ref"], arrays["d_in"],
             arrays["d_out"], arrays["x0"], arrays["xc0"], arrays["w0"], arrays["v0"], Y, YM, U, UA, FLAGS)
    keep = slice(n_pre, None)
    if not (np.all(np.isfinite(Y)) and np.all(np.isfinite(U))):
        Y, U = np.nan_to_num(Y, nan=np.inf), np.nan_to_num(U, nan=np.inf)
    return BatchResult(t[keep], arrays["ref"][:, keep], Y[:, keep], YM[:, keep], U[:, keep], UA[:, keep],
                       FLAGS[:, keep], dt, list(loops),
                       UA[:, n_pre - 1] if n_pre else arrays["w0"] + arrays["u0"])
