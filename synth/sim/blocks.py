"""Composable actuator and sensor blocks for the sampled simulation.

Every block is a small frozen dataclass with documented parameters and one
equation, applied once per simulation step ``dt`` to a signal in **absolute**
units (the operating point added: PWM, rad/s), so limits such as 0-255 PWM
apply as written. Blocks chain in lists: an actuator chain between the
controller and the plant, a sensor chain between the plant and the
controller; the same chains serve the closed loop
(:func:`synth.sim.simulate`) and the open loop
(:func:`synth.sim.simulate_open_loop`), one variant or a batch of them.

Each block compiles to an integer code, a parameter vector and a state
vector; the step equations below are the numba functions in
:mod:`synth.sim._steps` that the simulation kernel calls. ``block.apply(x, dt)``
runs a block (or ``apply_chain`` a list) on a signal by itself.

=============  ===================================================================
type           equation per step (input ``x_k``, output ``y_k``)
=============  ===================================================================
rate_limit     ``y_k = y_{k-1} + clip(x_k - y_{k-1}, -F dt, R dt)``
saturation     ``y_k = clip(x_k, min, max)``
dead_zone      ``y_k = c`` inside ``|x_k - c| <= w``, else ``x_k -+ w``
quantizer      ``y_k = o + q round((x_k - o)/q)`` (or ``floor``)
backlash       ``y_k = clip(y_{k-1}, x_k - w, x_k + w)`` (play of total width ``2w``)
static         piecewise-linear table ``y = f(x)``, ends extrapolated
lag            ``tau y' + y = k x`` (exact zero-order-hold discretization)
dynamics       any proper ``N(s)/D(s)`` (zero-order-hold discretization)
supply_sag     ``y = x V/V_n``, ``V = V_oc - R_i I``; brown-out below ``V_reset``
sample_hold    ``y_k = x_j`` at the last sample instant ``j T <= k dt``
noise          ``y_k = x_k + n_k`` (white Gaussian or from a PSD, seeded)
delay          pure delay; pooled with the loop delay (it commutes with every
               time-invariant block)
=============  ===================================================================
"""

from __future__ import annotations

import itertools
from dataclasses import asdict, dataclass, field
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError

P_MAX = 34
"""Length of every block's parameter vector (padded)."""
S_MAX = 8
"""Length of every block's state vector (padded; ``dynamics`` uses the upper half as scratch)."""
MAX_TABLE = 16
"""Most points of a ``static`` table."""
MAX_DYNAMICS_ORDER = 4
"""Highest order of a ``dynamics`` block that is not folded into the plant."""

IDENTITY, RATE_LIMIT, SATURATION, DEAD_ZONE, QUANTIZER, DYNAMICS, SUPPLY_SAG, SAMPLE_HOLD, NOISE, BACKLASH, \
    STATIC = range(11)


# ---------------------------------------------------------------------------------- Python classes
def _positive(name: str, value: float, kind: str, allow_zero: bool = False) -> float:
    value = float(value)
    ok = value >= 0 if allow_zero else value > 0
    if not np.isfinite(value) or not ok:
        raise ModelError(f"{kind}: {name} must be a finite number {'>=' if allow_zero else '>'} 0, got {value:g}")
    return value


class Block:
    """Base of every block.

    Attributes
    ----------
    kind : str
        The ``type:`` name used in spec files.
    code : int
        Integer code the simulation kernel dispatches on.
    linear : bool
        A linear time-invariant block (``lag``, ``dynamics``): folded exactly into the plant's
        discretization when it sits next to the plant.
    command_side : bool
        A block usually implemented in the controller or PWM generator (rate limit, saturation,
        quantizer); anti-windup tracks the output of the leading run of these.
    flag : str or None
        Name of the time a block spends active in step metrics (``"rate_limited"``,
        ``"saturated"``, ...).
    """

    kind: ClassVar[str] = ""
    code: ClassVar[int] = IDENTITY
    linear: ClassVar[bool] = False
    command_side: ClassVar[bool] = False
    flag: ClassVar[str | None] = None

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        """Parameter vector (length :data:`P_MAX`) for simulation step ``dt``.

        Examples
        --------
        >>> RateLimit(10000).parameters(0.001)[:2].tolist()  # R dt, F dt
        [10.0, 10.0]
        """
        return _pad([], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        """State vector (length :data:`S_MAX`) at rest with constant input ``x``.

        Examples
        --------
        >>> RateLimit(10000).initial_state(200.0, 0.001)[0]
        np.float64(200.0)
        """
        return _pad([], S_MAX)

    def dc_gain(self) -> float:
        """Static gain used to initialise the loop at rest (1 for nonlinear blocks).

        Examples
        --------
        >>> Saturation(0, 255).dc_gain(), Lag(0.1, gain=2.0).dc_gain()
        (1.0, 2.0)
        """
        return 1.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready ``{"type": kind, **parameters}``.

        Examples
        --------
        >>> Saturation(0, 255).to_dict()
        {'type': 'saturation', 'min': 0.0, 'max': 255.0}
        """
        return {"type": self.kind, **asdict(self)}  # type: ignore[call-overload]

    def apply(self, x: Any, dt: float, seed: int = 0) -> np.ndarray:
        """Run this block alone over the signal ``x`` sampled every ``dt`` s (state starts at rest).

        Examples
        --------
        >>> RateLimit(rate=1.0).apply([0, 0, 5, 5, 5], dt=1.0).tolist()
        [0.0, 0.0, 1.0, 2.0, 3.0]
        """
        return apply_chain([self], x, dt, seed)


def _pad(values: list[float], n: int) -> np.ndarray:
    out = np.zeros(n)
    out[: len(values)] = values
    return out


@dataclass(frozen=True)
class RateLimit(Block):
    """Slew-rate limiter: the output moves at most ``rate`` units/s up and ``falling`` down.

    ``y_k = y_{k-1} + clip(x_k - y_{k-1}, -falling dt, rate dt)``. The seed's B = 10 PWM/ms is
    ``RateLimit(rate=10000)``.

    Parameters
    ----------
    rate : float
        Largest rising rate (units/s, > 0).
    falling : float, optional
        Largest falling rate (default ``rate``).

    Examples
    --------
    >>> RateLimit(rate=2.0).apply([0, 10, 10, 10, -10], dt=1.0).tolist()
    [0.0, 2.0, 4.0, 6.0, 4.0]
    """

    rate: float
    falling: float | None = None
    kind: ClassVar[str] = "rate_limit"
    code: ClassVar[int] = RATE_LIMIT
    command_side: ClassVar[bool] = True
    flag: ClassVar[str | None] = "rate_limited"

    def __post_init__(self) -> None:
        if not (float(self.rate) > 0):
            raise ModelError(f"rate_limit: rate must be > 0 units/s, got {self.rate:g}")
        object.__setattr__(self, "rate", float(self.rate))
        if self.falling is not None:
            object.__setattr__(self, "falling", _positive("falling", self.falling, self.kind))

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        fall = self.rate if self.falling is None else self.falling
        return _pad([self.rate * dt, fall * dt], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        return _pad([x], S_MAX)


@dataclass(frozen=True)
class Saturation(Block):
    """Amplitude limits: ``y = clip(x, min, max)`` (e.g. the 0-255 PWM range).

    Examples
    --------
    >>> Saturation(0, 255).apply([-5, 100, 300], dt=0.001).tolist()
    [0.0, 100.0, 255.0]
    """

    min: float
    max: float
    kind: ClassVar[str] = "saturation"
    code: ClassVar[int] = SATURATION
    command_side: ClassVar[bool] = True
    flag: ClassVar[str | None] = "saturated"

    def __post_init__(self) -> None:
        lo, hi = float(self.min), float(self.max)
        if np.isnan(lo) or np.isnan(hi) or lo >= hi:
            raise ModelError(f"saturation: min ({lo:g}) must be below max ({hi:g})")
        object.__setattr__(self, "min", lo)
        object.__setattr__(self, "max", hi)

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return _pad([self.min, self.max], P_MAX)


@dataclass(frozen=True)
class DeadZone(Block):
    """Dead zone of half-width ``width`` around ``center``: no output change inside it.

    ``y = c`` for ``|x - c| <= w``, ``y = x - w`` above, ``y = x + w`` below.

    Examples
    --------
    >>> DeadZone(width=1.0).apply([-3, -0.5, 0.5, 3], dt=1.0).tolist()
    [-2.0, 0.0, 0.0, 2.0]
    """

    width: float
    center: float = 0.0
    kind: ClassVar[str] = "dead_zone"
    code: ClassVar[int] = DEAD_ZONE
    flag: ClassVar[str | None] = "in_dead_zone"

    def __post_init__(self) -> None:
        object.__setattr__(self, "width", _positive("width", self.width, self.kind, allow_zero=True))
        object.__setattr__(self, "center", float(self.center))

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return _pad([self.center, self.width], P_MAX)


@dataclass(frozen=True)
class Quantizer(Block):
    """Resolution ``step``: ``y = offset + step round((x - offset)/step)`` (``mode: floor`` truncates).

    The 255-step PWM is ``Quantizer(1)``; the seed's speed sensor resolves 1.2 rad/s.

    Examples
    --------
    >>> Quantizer(1.2).apply([0.5, 0.7, 2.0], dt=1.0).round(6).tolist()
    [0.0, 1.2, 2.4]
    """

    step: float
    offset: float = 0.0
    mode: str = "round"
    kind: ClassVar[str] = "quantizer"
    code: ClassVar[int] = QUANTIZER
    command_side: ClassVar[bool] = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "step", _positive("step", self.step, self.kind))
        if self.mode not in ("round", "floor"):
            raise ModelError(f"quantizer: mode must be 'round' or 'floor', got {self.mode!r}")

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return _pad([self.step, float(self.offset), 0.0 if self.mode == "round" else 1.0], P_MAX)


@dataclass(frozen=True)
class Backlash(Block):
    """Backlash (play) of total width ``width``: the output follows only once the input has
    crossed the gap, ``y_k = clip(y_{k-1}, x_k - width/2, x_k + width/2)``.

    Examples
    --------
    >>> Backlash(width=2.0).apply([0, 0.5, 2, 1.5, 0], dt=1.0).tolist()
    [0.0, 0.0, 1.0, 1.0, 1.0]
    """

    width: float
    kind: ClassVar[str] = "backlash"
    code: ClassVar[int] = BACKLASH
    flag: ClassVar[str | None] = "in_backlash"

    def __post_init__(self) -> None:
        object.__setattr__(self, "width", _positive("width", self.width, self.kind, allow_zero=True))

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return _pad([self.width / 2.0], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        return _pad([x], S_MAX)


@dataclass(frozen=True)
class Static(Block):
    """Static (memoryless) nonlinearity ``y = f(x)`` given as a table of points, linear in between
    and extrapolated along the end segments (a smooth curve: give enough points).

    Parameters
    ----------
    table : list of (x, y)
        2 to 16 points with strictly increasing ``x``.

    Examples
    --------
    >>> Static([(0, 0), (1, 2), (2, 3)]).apply([-1, 0.5, 1.5, 3], dt=1.0).tolist()
    [-2.0, 1.0, 2.5, 4.0]
    """

    table: tuple[tuple[float, float], ...]
    kind: ClassVar[str] = "static"
    code: ClassVar[int] = STATIC

    def __post_init__(self) -> None:
        pts = tuple((float(a), float(b)) for a, b in self.table)
        if not 2 <= len(pts) <= MAX_TABLE:
            raise ModelError(f"static: table needs 2 to {MAX_TABLE} points, got {len(pts)}")
        xs = [a for a, _ in pts]
        if not all(np.isfinite(v) for p in pts for v in p):
            raise ModelError("static: table values must be finite")
        if any(b <= a for a, b in itertools.pairwise(xs)):
            raise ModelError("static: table x values must be strictly increasing")
        object.__setattr__(self, "table", pts)

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        xs = [a for a, _ in self.table]
        ys = [b for _, b in self.table]
        return _pad([len(xs)] + xs + [0.0] * (MAX_TABLE - len(xs)) + ys, P_MAX)

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.kind, "table": [list(p) for p in self.table]}


@dataclass(frozen=True)
class Dynamics(Block):
    """Linear dynamics ``num(s)/den(s)`` (proper), e.g. a sensor filter or a resonance.

    Next to the plant (the end of the actuator chain, the start of the sensor chain) the block
    is folded into the plant's exact zero-order-hold discretization; elsewhere it is discretized
    on its own with a zero-order hold (exact when its input is piecewise constant, as after a
    sample-and-hold), up to order 4.

    Parameters
    ----------
    num, den : sequence of float
        Coefficients in descending powers of ``s``.
    text : str
        The transfer function as written (for reports).

    Examples
    --------
    >>> d = Dynamics.from_string("442/((s+45)*(s+9.7))")
    >>> round(d.dc_gain(), 4)
    1.0126
    """

    num: tuple[float, ...]
    den: tuple[float, ...]
    text: str = ""
    kind: ClassVar[str] = "dynamics"
    code: ClassVar[int] = DYNAMICS
    linear: ClassVar[bool] = True

    def __post_init__(self) -> None:
        from synth.plant import Plant

        plant = Plant(np.asarray(self.num, float), np.asarray(self.den, float))  # validates properness
        object.__setattr__(self, "num", tuple(float(v) for v in plant.num))
        object.__setattr__(self, "den", tuple(float(v) for v in plant.den))
        if plant.den[-1] == 0.0:
            raise ModelError(f"{self.kind}: {self.text or 'transfer function'} has a pole at s = 0; "
                             "a block must have a finite static gain")
        if np.any(np.roots(plant.den).real >= 0):
            raise ModelError(f"{self.kind}: {self.text or 'transfer function'} is unstable")

    @classmethod
    def from_string(cls, text: str) -> Dynamics:
        """Parse a transfer function such as ``"442/((s+45)*(s+9.7))"``.

        Examples
        --------
        >>> Dynamics.from_string("10/(s+10)").den
        (1.0, 10.0)
        """
        from synth.plant import Plant

        p = Plant.from_string(text)
        if p.delay:
            raise ModelError(f"dynamics: {text!r} has a delay; use a delay block")
        return cls(tuple(p.num), tuple(p.den), text)

    def dc_gain(self) -> float:
        return float(self.num[-1] / self.den[-1])

    def state_space(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Continuous ``(A, B, C, D)`` of the block.

        Examples
        --------
        >>> A, B, C, D = Dynamics.from_string("10/(s+10)").state_space()
        >>> A.tolist(), C.tolist()
        ([[-10.0]], [10.0])
        """
        from synth.sim.discretize import tf_to_ss

        return tf_to_ss(np.asarray(self.num), np.asarray(self.den))

    def _discrete(self, dt: float):
        from synth.sim.discretize import zoh

        A, B, C, D = self.state_space()
        Ad, Bd = zoh(A, B[:, None], dt)
        return Ad, Bd[:, 0], C, D

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        n = len(self.den) - 1
        if n > MAX_DYNAMICS_ORDER:
            raise ModelError(f"{self.kind}: order {n} is above {MAX_DYNAMICS_ORDER}; only blocks next to the "
                             "plant (folded into it) may be of higher order")
        Ad, Bd, C, D = self._discrete(dt)
        a = np.zeros((4, 4))
        a[:n, :n] = Ad
        return _pad([n, *a.ravel(), *_pad(list(Bd), 4), *_pad(list(C), 4), D], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        n = len(self.den) - 1
        if n == 0 or n > MAX_DYNAMICS_ORDER:
            return _pad([], S_MAX)
        Ad, Bd, _, _ = self._discrete(dt)
        xs = np.linalg.solve(np.eye(n) - Ad, Bd * x)
        return _pad(list(xs), S_MAX)

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.kind, "tf": self.text or _tf_text(self.num, self.den)}


def _tf_text(num: tuple[float, ...], den: tuple[float, ...]) -> str:
    from synth.polynomials import format_factored

    return format_factored(np.asarray(num), np.asarray(den), 6)


@dataclass(frozen=True, init=False)
class Lag(Dynamics):
    """First-order lag ``gain/(tau s + 1)`` (e.g. motor electrical or ESC filter).

    Examples
    --------
    >>> y = Lag(tau=1.0).apply(np.ones(4), dt=np.log(2.0))
    >>> y.round(4).tolist()
    [1.0, 1.0, 1.0, 1.0]
    """

    tau: float = 0.0
    gain: float = 1.0
    kind: ClassVar[str] = "lag"

    def __init__(self, tau: float, gain: float = 1.0) -> None:
        tau = _positive("tau", tau, "lag")
        object.__setattr__(self, "tau", tau)
        object.__setattr__(self, "gain", float(gain))
        Dynamics.__init__(self, (float(gain),), (tau, 1.0), f"{gain:g}/({tau:g}*s+1)")

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.kind, "tau": self.tau, "gain": self.gain}


@dataclass(frozen=True)
class SupplySag(Block):
    """Battery voltage sag and brown-out reset (seed 1, section 4B).

    The drive's gain is proportional to the battery's terminal voltage, which falls with the
    current drawn through the internal resistance; below ``v_reset`` (the 5 V regulator of the
    seed) the microprocessor resets and the drive output is ``output_in_reset`` for
    ``reset_time`` seconds:

    ``I = max(0, i_static x + i_dynamic (x - x_f))`` with ``tau x_f' + x_f = x`` (the back-EMF
    catches up with the command at the mechanical time constant ``tau``),
    ``V = v_open - r_internal I``, ``y = x V / v_nominal``.

    The current is computed from the block's input (the commanded throttle), which avoids an
    algebraic loop. ``v_nominal`` defaults to the steady voltage at the operating-point input,
    so the block's gain is 1 there (the plant model was identified at that voltage).

    Parameters
    ----------
    v_open : float
        Open-circuit battery voltage (V).
    r_internal : float
        Internal resistance (ohm).
    i_static : float
        Steady current per input unit (A/unit).
    i_dynamic : float
        Extra current per unit of ``x - x_f`` (A/unit): the inrush of a step command.
    tau : float
        Time constant of ``x_f`` (s).
    v_reset : float
        Brown-out voltage (V); the seed's 5 V.
    reset_time : float
        Time the drive stays off after a brown-out (s).
    v_nominal : float, optional
        Voltage at which the block's gain is 1.
    output_in_reset : float
        Drive output while in reset (input units; 0 = motor off).

    Examples
    --------
    >>> sag = SupplySag(v_open=16.8, r_internal=0.1, i_static=0.0, i_dynamic=2.0, tau=0.1)
    >>> y = sag.apply([100.0, 100.0, 160.0, 160.0], dt=0.001)
    >>> y.round(2).tolist()  # a 60-unit step draws 120 A: 12 V drop, brown-out (output 0)
    [100.0, 100.0, 0.0, 0.0]
    """

    v_open: float
    r_internal: float
    i_static: float = 0.0
    i_dynamic: float = 0.0
    tau: float = 0.1
    v_reset: float = 5.0
    reset_time: float = 0.05
    v_nominal: float | None = None
    output_in_reset: float = 0.0
    kind: ClassVar[str] = "supply_sag"
    code: ClassVar[int] = SUPPLY_SAG
    flag: ClassVar[str | None] = "brown_out"

    def __post_init__(self) -> None:
        for name in ("v_open", "tau"):
            object.__setattr__(self, name, _positive(name, getattr(self, name), self.kind))
        for name in ("r_internal", "i_static", "i_dynamic", "v_reset", "reset_time"):
            object.__setattr__(self, name, _positive(name, getattr(self, name), self.kind, allow_zero=True))
        if self.v_nominal is not None:
            object.__setattr__(self, "v_nominal", _positive("v_nominal", self.v_nominal, self.kind))

    def nominal_voltage(self, operating_input: float) -> float:
        """``v_nominal``, or the steady terminal voltage at ``operating_input``.

        Examples
        --------
        >>> round(SupplySag(v_open=16.8, r_internal=0.1, i_static=0.04).nominal_voltage(200), 6)
        16.0
        """
        if self.v_nominal is not None:
            return self.v_nominal
        v = self.v_open - self.r_internal * max(0.0, self.i_static * operating_input)
        if v <= 0:
            raise ModelError(f"supply_sag: the battery voltage at the operating point is {v:g} V (<= 0)")
        return v

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        a = float(np.exp(-dt / self.tau))
        reset_steps = max(1.0, float(np.round(self.reset_time / dt)))
        return _pad([self.v_open, self.nominal_voltage(operating_input), self.r_internal, self.i_static,
                     self.i_dynamic, a, self.v_reset, reset_steps, self.output_in_reset], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        return _pad([x, 0.0], S_MAX)


@dataclass(frozen=True)
class SampleHold(Block):
    """Sample-and-hold at ``rate`` Hz (e.g. the 400 Hz speed-sensor refresh of seed 1).

    Samples are taken at ``phase + j/rate`` seconds; each is read at the first simulation
    step at or after its instant (exact when ``1/rate`` is a multiple of ``dt``; otherwise the
    sampling instants are late by less than ``dt``) and held until the next.

    Examples
    --------
    >>> SampleHold(rate=0.5).apply([0, 1, 2, 3, 4], dt=1.0).tolist()
    [0.0, 0.0, 2.0, 2.0, 4.0]
    """

    rate: float
    phase: float = 0.0
    kind: ClassVar[str] = "sample_hold"
    code: ClassVar[int] = SAMPLE_HOLD

    def __post_init__(self) -> None:
        object.__setattr__(self, "rate", _positive("rate", self.rate, self.kind))
        object.__setattr__(self, "phase", _positive("phase", self.phase, self.kind, allow_zero=True))

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return _pad([1.0 / (self.rate * dt), self.phase / dt], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        return _pad([x, self.phase / dt], S_MAX)


@dataclass(frozen=True)
class Noise(Block):
    """Additive noise: white Gaussian of standard deviation ``std``, or shaped by a one-sided
    PSD table ``psd`` of ``(w [rad/s], S [unit^2/(rad/s)])`` points (log-log interpolated;
    variance = integral of S dw). Seeded: the same seed gives the same noise.

    Examples
    --------
    >>> y = Noise(std=0.5).apply(np.zeros(20000), dt=0.001, seed=1)
    >>> round(float(y.std()), 2)
    0.5
    """

    std: float = 0.0
    psd: tuple[tuple[float, float], ...] | None = None
    kind: ClassVar[str] = "noise"
    code: ClassVar[int] = NOISE

    def __post_init__(self) -> None:
        object.__setattr__(self, "std", _positive("std", self.std, self.kind, allow_zero=True))
        if self.psd is not None:
            from synth.sim.signals import validate_psd

            object.__setattr__(self, "psd", validate_psd(self.psd, "noise"))
        if self.std == 0.0 and self.psd is None:
            raise ModelError("noise: give std > 0 or a psd table")

    def samples(self, n: int, dt: float, rng: np.random.Generator) -> np.ndarray:
        """``n`` noise samples at step ``dt``.

        Examples
        --------
        >>> Noise(std=1.0).samples(3, 0.001, np.random.default_rng(0)).shape
        (3,)
        """
        from synth.sim.signals import psd_signal

        out = np.zeros(n)
        if self.std > 0:
            out += self.std * rng.standard_normal(n)
        if self.psd is not None:
            out += psd_signal(self.psd, n, dt, rng)
        return out

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"type": self.kind, "std": self.std}
        if self.psd is not None:
            d["psd"] = [list(p) for p in self.psd]
        return d


@dataclass(frozen=True)
class Delay(Block):
    """Pure delay of ``delay`` s. It is pooled with the loop delay (exact, fractional delays
    included): a delay commutes with every time-invariant block, so its place in a chain does
    not matter except relative to a sample-and-hold or noise.

    Examples
    --------
    >>> Delay(0.002).delay
    0.002
    """

    delay: float
    kind: ClassVar[str] = "delay"
    code: ClassVar[int] = IDENTITY

    def __post_init__(self) -> None:
        object.__setattr__(self, "delay", _positive("delay", self.delay, self.kind, allow_zero=True))


BLOCK_TYPES: dict[str, type[Block]] = {
    cls.kind: cls
    for cls in (RateLimit, Saturation, DeadZone, Quantizer, Backlash, Static, Lag, Dynamics, SupplySag,
                SampleHold, Noise, Delay)
}
"""Every block class by its ``type:`` name."""


@dataclass
class _ChainArrays:
    codes: np.ndarray
    params: np.ndarray
    state: np.ndarray
    noise: np.ndarray = field(default_factory=lambda: np.zeros((1, 1)))


def chain_arrays(blocks: list[Block], dt: float, x0: float, operating_input: float, n_steps: int,
                 rng: np.random.Generator | None) -> _ChainArrays:
    """Codes, parameters, initial states (at rest with input ``x0``) and noise of a chain.

    Examples
    --------
    >>> arr = chain_arrays([RateLimit(1000), Saturation(0, 1)], 0.001, 0.5, 0.5, 10, None)
    >>> arr.codes.tolist(), arr.state[0, 0]
    ([1, 2], np.float64(0.5))
    """
    codes = np.zeros(max(1, len(blocks)), np.int64)
    params = np.zeros((max(1, len(blocks)), P_MAX))
    state = np.zeros((max(1, len(blocks)), S_MAX))
    noises = []
    x = x0
    for i, b in enumerate(blocks):
        codes[i] = b.code
        params[i] = b.parameters(dt, operating_input)
        state[i] = b.initial_state(x, dt)
        if isinstance(b, Noise):
            params[i, 0] = len(noises)
            noises.append(b.samples(n_steps, dt, rng if rng is not None else np.random.default_rng(0)))
        x = x * b.dc_gain()
    noise = np.array(noises) if noises else np.zeros((1, max(1, n_steps)))
    return _ChainArrays(codes, params, state, noise)


def apply_chain(blocks: list[Block], x: Any, dt: float, seed: int = 0,
                return_flags: bool = False) -> Any:
    """Run a chain of blocks over the signal ``x`` (absolute units, sampled every ``dt`` s).

    The chain starts at rest with its first input value; linear blocks are discretized with a
    zero-order hold; a :class:`Delay` shifts the output by whole steps (rounded).

    Parameters
    ----------
    blocks : list of Block
    x : array_like
    dt : float
    seed : int
        Seed of any noise block.
    return_flags : bool
        Also return a boolean array ``(len(blocks), len(x))`` of the steps each block was active.

    Examples
    --------
    >>> apply_chain([RateLimit(10.0), Saturation(0, 3)], [0, 5, 5, 5], dt=0.1).tolist()
    [0.0, 1.0, 2.0, 3.0]
    """
    x = np.asarray(x, dtype=float).ravel()
    if not np.all(np.isfinite(x)):
        raise ModelError("input signal has non-finite values")
    if dt <= 0:
        raise ModelError(f"dt must be > 0 s, got {dt:g}")
    delay = sum(b.delay for b in blocks if isinstance(b, Delay))
    active = [b for b in blocks if not isinstance(b, Delay)]
    arr = chain_arrays(active, dt, float(x[0]) if x.size else 0.0, float(x[0]) if x.size else 0.0, x.size,
                       np.random.default_rng(seed))
    flags = np.zeros((arr.codes.size, x.size), dtype=np.bool_)
    from synth.sim._steps import run_chain

    if not active:
        y = x.copy()
    else:
        y = run_chain(arr.codes, arr.params, arr.state, arr.noise, x, flags)
    m = int(np.round(delay / dt))
    if m:
        y = np.concatenate([np.full(min(m, y.size), y[0] if y.size else 0.0), y[: max(0, y.size - m)]])
    if return_flags:
        return y, flags[: len(active)]
    return y
