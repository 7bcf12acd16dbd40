"""The sampled nonlinear closed loop (and open loop) of a plant, a controller and block chains.

The plant (rational part and exact delay) is discretized exactly for a
piecewise-constant input (zero-order hold); a delay that is not a whole
number of steps is handled exactly too (:mod:`synth.sim.discretize`).
Linear blocks next to the plant (the trailing end of the actuator chain, the
leading end of the sensor chain) are folded into the same exact
discretization, so a motor lag or a sensor filter costs no accuracy. The
controller is discretized at its own rate (Tustin by default) and its output
held between updates. Signals are in absolute units: the controller's output
is added to the operating-point input, the linear plant model acts on
deviations from the operating point, and its output is added to the
operating-point output.

The loop starts at rest: every state is set to the steady state of the loop
with each nonlinear block replaced by the identity at the initial reference
(give ``settle`` seconds to let the nonlinear loop find its own rest first).

Sampling convention: the output is sampled at ``k dt`` just before the
controller's new value takes effect (a biproper plant's direct feedthrough
therefore sees the previous input; there is no algebraic loop).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.errors import ModelError
from synth.plant import Plant
from synth.sim._kernel import SENSOR_BIT, run_loop
from synth.sim.blocks import (
    P_MAX,
    S_MAX,
    Block,
    Delay,
    chain_arrays,
)
from synth.sim.discretize import delayed_zoh, discretize_controller, tf_to_ss, zoh

Reference = float | np.ndarray | Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class OperatingPoint:
    """Trim input and output the linear plant model is linearized about (e.g. 200 PWM, 870 rad/s).

    Examples
    --------
    >>> OperatingPoint(200, 870).to_dict()
    {'input': 200.0, 'output': 870.0}
    """

    input: float = 0.0
    output: float = 0.0

    def __post_init__(self) -> None:
        for name in ("input", "output"):
            v = float(getattr(self, name))
            if not np.isfinite(v):
                raise ModelError(f"operating_point.{name} must be finite, got {v!r}")
            object.__setattr__(self, name, v)

    def to_dict(self) -> dict[str, float]:
        """JSON-ready dict."""
        return {"input": self.input, "output": self.output}


@dataclass(frozen=True, eq=False)
class NonlinearLoop:
    """Everything that defines the sampled closed loop.

    Parameters
    ----------
    plant : Plant
        Linear model about the operating point (deviation input -> deviation output), with its delay.
    controller : Controller
        Acts on ``reference - measured output``; its output is added to the operating-point input.
    actuator, sensor : sequence of Block
        Chains between controller and plant, and between plant and controller.
    dt : float
        Simulation step (s).
    controller_rate : float, optional
        Controller update rate (Hz); ``1/(rate dt)`` must be a whole number. Default ``1/dt``.
    loop_delay : float
        Extra delay inside the loop (s), added to the plant's delay and any delay block.
    operating_point : OperatingPoint
    discretization : str
        Controller discretization: ``tustin``, ``zoh``, ``backward_euler``, ``forward_euler``.
    anti_windup : bool
        Drive the controller's state with the output of the leading rate-limit/saturation/
        quantizer blocks instead of its own output (observer form; needs a biproper controller
        with stable zeros, e.g. PI). Without limits active it changes nothing.
    label : str
        Name in reports.

    Examples
    --------
    >>> from synth.sim.blocks import RateLimit, Saturation
    >>> loop = NonlinearLoop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3}),
    ...                      actuator=[RateLimit(10000), Saturation(0, 255)],
    ...                      operating_point=OperatingPoint(200, 870))
    >>> loop.total_delay, loop.controller_period
    (0.0, 0.001)
    """

    plant: Plant
    controller: Controller
    actuator: tuple[Block, ...] = ()
    sensor: tuple[Block, ...] = ()
    dt: float = 1e-3
    controller_rate: float | None = None
    loop_delay: float = 0.0
    operating_point: OperatingPoint = field(default_factory=OperatingPoint)
    discretization: str = "tustin"
    anti_windup: bool = False
    label: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "actuator", tuple(self.actuator))
        object.__setattr__(self, "sensor", tuple(self.sensor))
        for b in (*self.actuator, *self.sensor):
            if not isinstance(b, Block):
                raise ModelError(f"expected a simulation block, got {b!r}")
        if not (np.isfinite(self.dt) and self.dt > 0):
            raise ModelError(f"dt must be > 0 s, got {self.dt!r}")
        if not (np.isfinite(self.loop_delay) and self.loop_delay >= 0):
            raise ModelError(f"loop_delay must be >= 0 s, got {self.loop_delay!r}")
        if len(self.actuator) > 16 or len(self.sensor) > 15:
            raise ModelError("at most 16 actuator and 15 sensor blocks")
        _ = self.controller_ratio  # validates the rate
        if self.discretization not in ("tustin", "zoh", "backward_euler", "forward_euler"):
            raise ModelError(f"unknown controller discretization {self.discretization!r}; expected tustin, "
                             "zoh, backward_euler or forward_euler")

    # ------------------------------------------------------------------ derived
    @property
    def controller_ratio(self) -> int:
        """Simulation steps per controller update."""
        if self.controller_rate is None:
            return 1
        ratio = 1.0 / (float(self.controller_rate) * self.dt)
        if not (np.isfinite(ratio) and ratio >= 1 - 1e-9 and abs(ratio - round(ratio)) <= 1e-6 * ratio):
            raise ModelError(f"controller_rate {self.controller_rate:g} Hz must be 1/dt divided by a whole "
                             f"number (dt = {self.dt:g} s)")
        return round(ratio)

    @property
    def controller_period(self) -> float:
        """Controller sample period (s)."""
        return self.controller_ratio * self.dt

    @property
    def total_delay(self) -> float:
        """Plant delay + loop delay + delay blocks (s)."""
        blocks = sum(b.delay for b in (*self.actuator, *self.sensor) if isinstance(b, Delay))
        return self.plant.delay + self.loop_delay + blocks

    def replace(self, **changes: Any) -> NonlinearLoop:
        """Copy with fields replaced (e.g. ``controller=...``, ``loop_delay=0.01``).

        Examples
        --------
        >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}))
        >>> loop.replace(loop_delay=0.01).total_delay
        0.01
        """
        return dataclasses.replace(self, **changes)

    def with_gain(self, name: str, value: float) -> NonlinearLoop:
        """Copy with one controller parameter replaced.

        Examples
        --------
        >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}))
        >>> str(loop.with_gain("kp", 4).controller)
        'P(kp=4)'
        """
        return self.replace(controller=self.controller.with_parameters(**{name: value}))

    def without(self, *kinds: str) -> NonlinearLoop:
        """Copy without the blocks of the given types (e.g. ``"rate_limit"``).

        Examples
        --------
        >>> from synth.sim.blocks import RateLimit, Saturation
        >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}),
        ...                      actuator=[RateLimit(1.0), Saturation(-1, 1)])
        >>> [b.kind for b in loop.without("rate_limit").actuator]
        ['saturation']
        """
        return self.replace(actuator=tuple(b for b in self.actuator if b.kind not in kinds),
                            sensor=tuple(b for b in self.sensor if b.kind not in kinds))

    def linear(self) -> NonlinearLoop:
        """Copy with every nonlinear block removed (linear dynamics, delays and sample-holds stay).

        Examples
        --------
        >>> from synth.sim.blocks import Lag, Saturation
        >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}),
        ...                      actuator=[Saturation(-1, 1), Lag(0.01)])
        >>> [b.kind for b in loop.linear().actuator]
        ['lag']
        """
        keep = ("lag", "dynamics", "delay", "sample_hold")
        return self.replace(actuator=tuple(b for b in self.actuator if b.kind in keep),
                            sensor=tuple(b for b in self.sensor if b.kind in keep))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description.

        Examples
        --------
        >>> NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 2})).to_dict()["controller"]
        'P(kp=2)'
        """
        return {
            "plant": self.plant.to_string(6),
            "controller": str(self.controller),
            "dt": self.dt,
            "controller_rate": 1.0 / self.controller_period,
            "controller_discretization": self.discretization,
            "loop_delay": self.loop_delay,
            "total_delay": self.total_delay,
            "operating_point": self.operating_point.to_dict(),
            "actuator": [b.to_dict() for b in self.actuator],
            "sensor": [b.to_dict() for b in self.sensor],
            "anti_windup": self.anti_windup,
            "label": self.label,
        }


# ------------------------------------------------------------------------------------- results
@dataclass(eq=False)
class SimResult:
    """Time series of one simulated run (absolute units).

    Attributes
    ----------
    t : ndarray
        Time (s).
    reference : ndarray
        Reference (closed loop) or the applied input command (open loop).
    output : ndarray
        True plant output (with any output disturbance).
    measured : ndarray
        Output of the sensor chain (what the controller sees).
    command : ndarray
        Controller output plus the operating-point input (closed loop), or the input (open loop).
    actuator : ndarray
        Output of the actuator chain's blocks (before trailing linear blocks folded into the plant).
    flags : ndarray of int32
        Per step, bit ``i`` set when actuator block ``i`` was active, bit ``16 + i`` for sensor block ``i``.
    dt : float
    actuator_blocks, sensor_blocks : list of str
        Block types in chain order (for reading ``flags``).
    actuator_flags, sensor_flags : list of str or None
        Each block's metric name (``"rate_limited"``, ``"saturated"``, ...).
    label : str
    actuator_rest : float
        Actuator output at rest before ``t = 0`` (plant input units).
    """

    t: np.ndarray
    reference: np.ndarray
    output: np.ndarray
    measured: np.ndarray
    command: np.ndarray
    actuator: np.ndarray
    flags: np.ndarray
    dt: float
    actuator_blocks: list[str]
    sensor_blocks: list[str]
    actuator_flags: list[str | None]
    sensor_flags: list[str | None]
    label: str = ""
    actuator_rest: float = float("nan")

    def active(self, name: str) -> np.ndarray:
        """Steps where any block with metric ``name`` (e.g. ``"saturated"``) was active.

        Examples
        --------
        >>> from synth.sim.blocks import Saturation
        >>> r = simulate_open_loop(Plant.from_string("1/(s+1)"), [0.0, 2.0, 2.0], 0.1,
        ...                        actuator=[Saturation(-1, 1)])
        >>> r.active("saturated").tolist()
        [False, True, True]
        """
        mask = np.zeros(self.t.size, dtype=bool)
        for i, f in enumerate(self.actuator_flags):
            if f == name:
                mask |= (self.flags >> i) & 1 == 1
        for i, f in enumerate(self.sensor_flags):
            if f == name:
                mask |= (self.flags >> (SENSOR_BIT + i)) & 1 == 1
        return mask

    def time_active(self, name: str) -> float:
        """Seconds during which blocks with metric ``name`` were active.

        Examples
        --------
        >>> from synth.sim.blocks import Saturation
        >>> r = simulate_open_loop(Plant.from_string("1/(s+1)"), [0.0, 2.0, 2.0], 0.1,
        ...                        actuator=[Saturation(-1, 1)])
        >>> round(r.time_active("saturated"), 6)
        0.2
        """
        return float(np.count_nonzero(self.active(name)) * self.dt)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (the time series are in :meth:`series`).

        Examples
        --------
        >>> r = simulate_open_loop(Plant.from_string("1/(s+1)"), [0.0, 1.0, 1.0], 0.1)
        >>> r.to_dict()["steps"]
        3
        """
        names = sorted({f for f in self.actuator_flags + self.sensor_flags if f})
        return {"label": self.label, "dt": self.dt, "steps": int(self.t.size), "t_end": float(self.t[-1]),
                "actuator_blocks": self.actuator_blocks, "sensor_blocks": self.sensor_blocks,
                "time_active": {n: self.time_active(n) for n in names},
                "output_final": float(self.output[-1]), "actuator_rest": self.actuator_rest}

    def series(self) -> dict[str, np.ndarray]:
        """Columns for a CSV file.

        Examples
        --------
        >>> r = simulate_open_loop(Plant.from_string("1/(s+1)"), [0.0, 1.0], 0.1)
        >>> list(r.series())
        ['t', 'reference', 'output', 'measured', 'command', 'actuator']
        """
        cols = {"t": self.t, "reference": self.reference, "output": self.output, "measured": self.measured,
                "command": self.command, "actuator": self.actuator}
        for name in sorted({f for f in self.actuator_flags + self.sensor_flags if f}):
            cols[name] = self.active(name).astype(int)
        return cols


@dataclass(eq=False)
class BatchResult:
    """Time series of a batch of variants: arrays of shape ``(variants, steps)``.

    ``result[i]`` is the :class:`SimResult` of variant ``i``.
    """

    t: np.ndarray
    reference: np.ndarray
    output: np.ndarray
    measured: np.ndarray
    command: np.ndarray
    actuator: np.ndarray
    flags: np.ndarray
    dt: float
    loops: list[Any]
    actuator_rest: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __len__(self) -> int:
        return self.output.shape[0]

    def __getitem__(self, i: int) -> SimResult:
        chains = self._chains(i)
        ref = self.reference[i if self.reference.shape[0] > 1 else 0]
        return SimResult(self.t, ref, self.output[i], self.measured[i], self.command[i], self.actuator[i],
                         self.flags[i], self.dt, [b.kind for b in chains[0]], [b.kind for b in chains[1]],
                         [b.flag for b in chains[0]], [b.flag for b in chains[1]],
                         getattr(self.loops[i], "label", ""),
                         float(self.actuator_rest[i]) if self.actuator_rest.size else float("nan"))

    def _chains(self, i: int) -> tuple[list[Block], list[Block]]:
        loop = self.loops[i]
        act = [b for b in loop.actuator if not isinstance(b, Delay)]
        sen = [b for b in loop.sensor if not isinstance(b, Delay)]
        folded_a, folded_s = _fold_counts(act, sen)
        return act[: len(act) - folded_a], sen[folded_s:]

    def __iter__(self):
        return (self[i] for i in range(len(self)))


# ------------------------------------------------------------------------------------- building
def _fold_counts(act: list[Block], sen: list[Block]) -> tuple[int, int]:
    a = 0
    while a < len(act) and act[len(act) - 1 - a].linear:
        a += 1
    s = 0
    while s < len(sen) and sen[s].linear:
        s += 1
    return a, s


def _series_tf(blocks: list[Block]) -> tuple[np.ndarray, np.ndarray]:
    num, den = np.array([1.0]), np.array([1.0])
    for b in blocks:
        num = np.polymul(num, b.num)  # type: ignore[attr-defined]
        den = np.polymul(den, b.den)  # type: ignore[attr-defined]
    return num, den


@dataclass
class _Core:
    """Continuous plant core with inputs [w, d_in, d_out] and outputs [y_true, y_sensed] (deviations)."""

    A: np.ndarray
    B: np.ndarray  # n x 3
    C: np.ndarray  # 2 x n
    D: np.ndarray  # 2 x 3
    input_offset: float  # constant added to d_in: (H(0) - 1) u0
    sensed_offset: float  # F(0) y0


def _core(plant: Plant, folded_act: list[Block], folded_sen: list[Block], op: OperatingPoint) -> _Core:
    Aa, Ba, Ca, Da = tf_to_ss(*_series_tf(folded_act))
    Ag, Bg, Cg, Dg = tf_to_ss(plant.num, plant.den)
    Af, Bf, Cf, Df = tf_to_ss(*_series_tf(folded_sen))
    na, ng, nf = Aa.shape[0], Ag.shape[0], Af.shape[0]
    n = na + ng + nf
    A = np.zeros((n, n))
    B = np.zeros((n, 3))
    C = np.zeros((2, n))
    D = np.zeros((2, 3))
    ia, ig, i_f = slice(0, na), slice(na, na + ng), slice(na + ng, n)
    A[ia, ia] = Aa
    A[ig, ia] = np.outer(Bg, Ca)
    A[ig, ig] = Ag
    A[i_f, ia] = np.outer(Bf, Dg * Ca)
    A[i_f, ig] = np.outer(Bf, Cg)
    A[i_f, i_f] = Af
    B[ia, 0] = Ba
    B[ig, 0] = Bg * Da
    B[ig, 1] = Bg
    B[i_f, 0] = Bf * Dg * Da
    B[i_f, 1] = Bf * Dg
    B[i_f, 2] = Bf
    C[0, ia] = Dg * Ca
    C[0, ig] = Cg
    C[1, ia] = Df * Dg * Ca
    C[1, ig] = Df * Cg
    C[1, i_f] = Cf
    D[0] = [Dg * Da, Dg, 1.0]
    D[1] = [Df * Dg * Da, Df * Dg, Df]
    h0 = float(np.prod([b.dc_gain() for b in folded_act])) if folded_act else 1.0
    f0 = float(np.prod([b.dc_gain() for b in folded_sen])) if folded_sen else 1.0
    return _Core(A, B, C, D, (h0 - 1.0) * op.input, f0 * op.output)


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
    act: Any
    sen: Any
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


def _compile(loop: Any, mode: int, ref: np.ndarray, rest: float, d_in: np.ndarray, d_out: np.ndarray,
             rng: np.random.Generator) -> _Compiled:
    dt = loop.dt
    op = loop.operating_point
    act = [b for b in loop.actuator if not isinstance(b, Delay)]
    sen = [b for b in loop.sensor if not isinstance(b, Delay)]
    na_fold, ns_fold = _fold_counts(act, sen)
    act_x, act_f = act[: len(act) - na_fold], act[len(act) - na_fold:]
    sen_f, sen_x = sen[:ns_fold], sen[ns_fold:]
    core = _core(loop.plant, act_f, sen_f, op)
    n = core.A.shape[0]
    dz = delayed_zoh(core.A, core.B[:, 0], dt, loop.total_delay)
    _, Bd = zoh(core.A, core.B[:, 1:], dt)
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


def _run(loops: Sequence[Any], mode: int, inputs: Sequence[np.ndarray], t_end: float, disturbances: Sequence[Any],
         seed: int, settle: float) -> BatchResult:
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


# ------------------------------------------------------------------------------------- public API
def simulate(loop: NonlinearLoop, reference: Reference, t_end: float, disturbances: Sequence[Any] = (),
             seed: int = 0, settle: float = 0.0) -> SimResult:
    """Simulate the sampled closed loop from 0 to ``t_end`` seconds.

    Parameters
    ----------
    loop : NonlinearLoop
    reference : float, array or callable
        Reference in absolute output units: a constant, one value per step
        (``round(t_end/dt) + 1`` values) or a function of the time array.
    t_end : float
        Simulated time (s).
    disturbances : sequence
        :class:`~synth.sim.signals.PsdDisturbance`, :class:`~synth.sim.signals.RecordDisturbance`
        or :class:`~synth.sim.signals.StepDisturbance` objects (at the plant input or output).
    seed : int
        Seed of every random signal (noise blocks, PSD disturbances).
    settle : float
        Seconds simulated before ``t = 0`` at the initial reference and dropped.

    Returns
    -------
    SimResult

    Examples
    --------
    >>> from synth.sim.blocks import RateLimit, Saturation
    >>> from synth.sim.signals import step_reference
    >>> loop = NonlinearLoop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3}),
    ...                      actuator=[RateLimit(10000), Saturation(0, 255)],
    ...                      operating_point=OperatingPoint(200, 870))
    >>> r = simulate(loop, step_reference(820, 920), 0.5)
    >>> round(float(r.output[0]), 2), round(float(r.output[-1]), 2)  # P control: steady-state error
    (827.44, 914.64)
    >>> round(r.time_active("saturated"), 3)  # the step asks for 477 PWM; 255 is the top
    0.05
    """
    return _run([loop], 0, [reference], t_end, disturbances, seed, settle)[0]


def simulate_step(loop: NonlinearLoop, start: float, end: float, t_end: float, t_step: float = 0.0,
                  disturbances: Sequence[Any] = (), seed: int = 0, settle: float = 0.0) -> SimResult:
    """Response to a reference step from ``start`` to ``end`` (absolute output units) at ``t_step``,
    starting at rest at ``start``.

    Examples
    --------
    >>> loop = NonlinearLoop(Plant.from_string("10/(s+10)"), Controller.from_string("PI(1, 10)"))
    >>> r = simulate_step(loop, 0.0, 2.0, 1.0, t_step=0.1)
    >>> float(r.output[100]), round(float(r.output[-1]), 4)
    (0.0, 2.0)
    """
    from synth.sim.signals import step_reference

    return simulate(loop, step_reference(start, end, t_step), t_end, disturbances, seed, settle)


def simulate_batch(loops: Sequence[NonlinearLoop], reference: Reference | Sequence[Reference], t_end: float,
                   disturbances: Sequence[Any] = (), seed: int = 0, settle: float = 0.0) -> BatchResult:
    """Simulate many variants at once (sweeps, Monte Carlo): one compiled call for the batch.

    Variants may differ in anything (plant, controller, blocks, delay) except ``dt``. Random
    signals of variant ``i`` use the seed ``[seed, i]``: reproducible and independent.

    Parameters
    ----------
    loops : sequence of NonlinearLoop
    reference : reference, list of references or 2-D array
        One reference for all (a constant, a 1-D array of samples or a callable), or one per
        variant (a list, or one row per variant).

    Examples
    --------
    >>> base = NonlinearLoop(Plant.from_string("10/(s+10)"), Controller("P", {"kp": 1}))
    >>> batch = simulate_batch([base.with_gain("kp", k) for k in (1, 4, 9)], 1.0, 1.0)
    >>> batch.output[:, -1].round(3).tolist()  # K G0/(1 + K G0)
    [0.5, 0.8, 0.9]
    """
    loops = list(loops)
    if isinstance(reference, list | tuple):
        refs = list(reference)
        if len(refs) != len(loops):
            raise ModelError(f"{len(refs)} references for {len(loops)} variants")
    elif isinstance(reference, np.ndarray) and reference.ndim == 2:
        refs = list(reference)
        if len(refs) != len(loops):
            raise ModelError(f"{len(refs)} references for {len(loops)} variants")
    else:
        refs = [reference] * len(loops)
    return _run(loops, 0, refs, t_end, disturbances, seed, settle)


@dataclass(frozen=True, eq=False)
class OpenLoop:
    """Open-loop chain ``u -> actuator blocks -> plant (delay) -> sensor blocks -> y``."""

    plant: Plant
    actuator: tuple[Block, ...] = ()
    sensor: tuple[Block, ...] = ()
    dt: float = 1e-3
    loop_delay: float = 0.0
    operating_point: OperatingPoint = field(default_factory=OperatingPoint)
    label: str = ""

    @property
    def total_delay(self) -> float:
        """Plant delay + extra delay + delay blocks (s)."""
        blocks = sum(b.delay for b in (*self.actuator, *self.sensor) if isinstance(b, Delay))
        return self.plant.delay + self.loop_delay + blocks


def simulate_open_loop(plant: Plant, u: Any, dt: float, actuator: Sequence[Block] = (),
                       sensor: Sequence[Block] = (), operating_point: OperatingPoint | None = None,
                       delay: float = 0.0, disturbances: Sequence[Any] = (), seed: int = 0) -> SimResult:
    """Drive ``u -> actuator blocks -> plant -> sensor blocks -> y`` with a sampled input record.

    The input is absolute (e.g. PWM) and held constant over each step ``dt``; the plant model
    acts on its deviation from ``operating_point.input`` and its output is added to
    ``operating_point.output``. The chain starts at rest at the first input value. This is the
    model a measured input record is pushed through to compare with the measured output.

    Parameters
    ----------
    plant : Plant
    u : array_like
        Input samples, one per step.
    dt : float
        Sample time (s).
    actuator, sensor : sequence of Block
    operating_point : OperatingPoint, optional
    delay : float
        Extra delay (s) besides the plant's.
    disturbances, seed
        As in :func:`simulate`.

    Examples
    --------
    >>> from synth.sim.blocks import RateLimit
    >>> G = Plant.from_string("1/(0.01*s+1)")
    >>> r = simulate_open_loop(G, [0.0] + [1.0] * 200, 0.001, actuator=[RateLimit(50.0)])
    >>> r.actuator[:4].tolist(), round(float(r.output[-1]), 3)
    ([0.0, 0.05, 0.1, 0.15], 1.0)
    """
    u = np.asarray(u, float).ravel()
    if u.size < 2:
        raise ModelError("the input record needs at least 2 samples")
    loop = OpenLoop(plant, tuple(actuator), tuple(sensor), float(dt), float(delay),
                    operating_point or OperatingPoint())
    if not (np.isfinite(loop.dt) and loop.dt > 0):
        raise ModelError(f"dt must be > 0 s, got {dt!r}")
    return _run([loop], 1, [u], (u.size - 1) * loop.dt, disturbances, seed, 0.0)[0]


def simulate_open_loop_batch(loops: Sequence[OpenLoop], u: Any, disturbances: Sequence[Any] = (),
                             seed: int = 0) -> BatchResult:
    """:func:`simulate_open_loop` for many variants (e.g. candidate augmentations) at once.

    ``u`` is one input record for all variants, or one per variant (same length).

    Examples
    --------
    >>> from synth.sim.blocks import Saturation
    >>> G = Plant.from_string("1/(0.01*s+1)")
    >>> loops = [OpenLoop(G, (Saturation(-a, a),), dt=0.001) for a in (0.5, 2.0)]
    >>> simulate_open_loop_batch(loops, [0.0] + [1.0] * 200).output[:, -1].round(3).tolist()
    [0.5, 1.0]
    """
    loops = list(loops)
    arr = np.asarray(u, float)
    records = [arr] * len(loops) if arr.ndim == 1 else list(arr)
    if len(records) != len(loops):
        raise ModelError(f"{len(records)} input records for {len(loops)} variants")
    n = records[0].size
    return _run(loops, 1, records, (n - 1) * loops[0].dt, disturbances, seed, 0.0)
