"""The block interface, and chains of blocks run in series.

:class:`Block` is what every actuator and sensor block implements: an integer code, a parameter
vector and a state vector in the layout of :mod:`synth.sim.layout`, which the compiled step
equations (``synth.sim._steps``) read. :func:`chain_arrays` lays a chain out for the kernel;
:func:`apply_chain` runs one by itself. The two blocks the chain handles itself live here too:
:class:`Noise` (its samples are drawn when the chain is laid out) and :class:`Delay` (pooled
with the loop delay, or a whole-step shift of a chain's output).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.sim.layout import IDENTITY, NOISE, P_MAX, S_MAX

__all__ = ["Block", "ChainArrays", "Delay", "Noise", "apply_chain", "chain_arrays", "checked_positive", "padded"]


def checked_positive(name: str, value: float, kind: str, allow_zero: bool = False) -> float:
    """``value`` as a float, or a :class:`~synth.errors.ModelError` naming the block ``kind`` and ``name``.

    Parameters
    ----------
    name : str
        Parameter name (in the message).
    value : float
    kind : str
        Block type (in the message).
    allow_zero : bool
        Accept 0.

    Examples
    --------
    >>> checked_positive("rate", 2, "rate_limit")
    2.0
    >>> checked_positive("width", -1, "dead_zone", allow_zero=True)
    Traceback (most recent call last):
    ...
    synth.errors.ModelError: dead_zone: width must be a finite number >= 0, got -1
    """
    value = float(value)
    ok = value >= 0 if allow_zero else value > 0
    if not np.isfinite(value) or not ok:
        raise ModelError(f"{kind}: {name} must be a finite number {'>=' if allow_zero else '>'} 0, got {value:g}")
    return value


def padded(values: list[float], n: int) -> np.ndarray:
    """``values`` followed by zeros up to length ``n`` (a block's parameter or state vector).

    Examples
    --------
    >>> padded([1.0, 2.0], 4).tolist()
    [1.0, 2.0, 0.0, 0.0]
    """
    out = np.zeros(n)
    out[: len(values)] = values
    return out


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
        >>> from synth.sim.blocks import RateLimit
        >>> RateLimit(10000).parameters(0.001)[:2].tolist()  # R dt, F dt
        [10.0, 10.0]
        """
        return padded([], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        """State vector (length :data:`S_MAX`) at rest with constant input ``x``.

        Examples
        --------
        >>> from synth.sim.blocks import RateLimit
        >>> RateLimit(10000).initial_state(200.0, 0.001)[0]
        np.float64(200.0)
        """
        return padded([], S_MAX)

    def dc_gain(self) -> float:
        """Static gain used to initialise the loop at rest (1 for nonlinear blocks).

        Examples
        --------
        >>> from synth.sim.blocks import Lag, Saturation
        >>> Saturation(0, 255).dc_gain(), Lag(0.1, gain=2.0).dc_gain()
        (1.0, 2.0)
        """
        return 1.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready ``{"type": kind, **parameters}``.

        Examples
        --------
        >>> from synth.sim.blocks import Saturation
        >>> Saturation(0, 255).to_dict()
        {'type': 'saturation', 'min': 0.0, 'max': 255.0}
        """
        return {"type": self.kind, **asdict(self)}  # type: ignore[call-overload]

    def apply(self, x: Any, dt: float, seed: int = 0) -> np.ndarray:
        """Run this block alone over the signal ``x`` sampled every ``dt`` s (state starts at rest).

        Examples
        --------
        >>> from synth.sim.blocks import RateLimit
        >>> RateLimit(rate=1.0).apply([0, 0, 5, 5, 5], dt=1.0).tolist()
        [0.0, 0.0, 1.0, 2.0, 3.0]
        """
        return apply_chain([self], x, dt, seed)



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
        object.__setattr__(self, "std", checked_positive("std", self.std, self.kind, allow_zero=True))
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
        object.__setattr__(self, "delay", checked_positive("delay", self.delay, self.kind, allow_zero=True))



@dataclass
class ChainArrays:
    """A chain laid out for the kernel: one row per block.

    Attributes
    ----------
    codes : ndarray of int64
        Block codes (:mod:`synth.sim.layout`).
    params : ndarray
        Parameter vectors, ``(blocks, P_MAX)``.
    state : ndarray
        Initial states, ``(blocks, S_MAX)``.
    noise : ndarray
        Samples of the chain's noise blocks, ``(noise blocks, steps)``.

    Examples
    --------
    >>> ChainArrays(np.zeros(1, np.int64), np.zeros((1, P_MAX)), np.zeros((1, S_MAX))).noise.shape
    (1, 1)
    """

    codes: np.ndarray
    params: np.ndarray
    state: np.ndarray
    noise: np.ndarray = field(default_factory=lambda: np.zeros((1, 1)))


def chain_arrays(blocks: list[Block], dt: float, x0: float, operating_input: float, n_steps: int,
                 rng: np.random.Generator | None) -> ChainArrays:
    """Codes, parameters, initial states (at rest with input ``x0``) and noise of a chain.

    Examples
    --------
    >>> from synth.sim.blocks import RateLimit, Saturation
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
    return ChainArrays(codes, params, state, noise)


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
    >>> from synth.sim.blocks import RateLimit, Saturation
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
