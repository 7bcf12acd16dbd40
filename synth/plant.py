"""Plant models: a continuous-time SISO rational transfer function times an exact delay.

The frequency response is evaluated exactly, ``G(jw) = num(jw)/den(jw) *
exp(-j*w*delay)``; no Pade approximation is used in the frequency domain.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.polynomials import format_factored, trim
from synth.tfparse import parse_tf


@dataclass(frozen=True)
class Signal:
    """Name and unit of a plant input or output.

    Examples
    --------
    >>> Signal("throttle", "PWM").label()
    'throttle [PWM]'
    """

    name: str = "u"
    unit: str = ""

    def label(self) -> str:
        """Return ``"name [unit]"`` (or just the name without a unit)."""
        return f"{self.name} [{self.unit}]" if self.unit else self.name


@dataclass(frozen=True, eq=False)
class Plant:
    """A rational transfer function times ``exp(-delay*s)``.

    Parameters
    ----------
    num, den : array_like
        Polynomial coefficients in descending powers of ``s``.
    delay : float
        Pure time delay in seconds (>= 0).
    input, output : Signal
        Names and units of the input and output.
    label : str
        Free text used in reports (e.g. ``"low battery"``).

    Examples
    --------
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
    >>> round(G.dc_gain(), 4)
    1.9078
    >>> abs(G.freqresp([10.0])[0]).round(3)
    np.float64(1.658)
    """

    num: np.ndarray
    den: np.ndarray
    delay: float = 0.0
    input: Signal = field(default_factory=lambda: Signal("u", ""))
    output: Signal = field(default_factory=lambda: Signal("y", ""))
    label: str = ""

    def __post_init__(self) -> None:
        num = trim(np.asarray(self.num, dtype=float))
        den = trim(np.asarray(self.den, dtype=float))
        if den.size == 1 and den[0] == 0.0:
            raise ModelError("denominator is zero")
        if not (np.all(np.isfinite(num)) and np.all(np.isfinite(den))):
            raise ModelError("coefficients must be finite")
        if num.size > den.size and np.any(num != 0):
            raise ModelError(
                f"improper transfer function (numerator degree {num.size - 1} > "
                f"denominator degree {den.size - 1})"
            )
        if not np.isfinite(self.delay) or self.delay < 0:
            raise ModelError(f"delay must be a finite number >= 0 s, got {self.delay!r}")
        lead = den[0]
        object.__setattr__(self, "num", num / lead)
        object.__setattr__(self, "den", den / lead)
        object.__setattr__(self, "delay", float(self.delay))

    # ----------------------------------------------------------------- creation
    @classmethod
    def from_string(
        cls,
        text: str,
        delay: float = 0.0,
        input: Signal | None = None,
        output: Signal | None = None,
        label: str = "",
    ) -> Plant:
        """Parse ``text`` (see :func:`synth.tfparse.parse_tf`); ``delay`` adds to any ``exp``.

        Examples
        --------
        >>> Plant.from_string("exp(-0.01*s)/(s+1)", delay=0.01).delay
        0.02
        """
        parsed = parse_tf(text)
        return cls(
            np.array(parsed.num),
            np.array(parsed.den),
            parsed.delay + float(delay),
            input or Signal("u", ""),
            output or Signal("y", ""),
            label,
        )

    @classmethod
    def from_control(cls, sys: Any, delay: float = 0.0, **kwargs: Any) -> Plant:
        """Build a plant from a SISO python-control ``TransferFunction`` or ``StateSpace``.

        Examples
        --------
        >>> import control
        >>> Plant.from_control(control.tf([2.0], [1.0, 3.0]), delay=0.1).delay
        0.1
        """
        import control

        if isinstance(sys, control.StateSpace):
            sys = control.ss2tf(sys)
        if not isinstance(sys, control.TransferFunction):
            raise ModelError(f"expected a python-control TransferFunction, got {type(sys).__name__}")
        if sys.ninputs != 1 or sys.noutputs != 1:
            raise ModelError("only SISO systems are supported")
        if not sys.isctime():
            raise ModelError("only continuous-time systems are supported")
        return cls(np.asarray(sys.num[0][0], float), np.asarray(sys.den[0][0], float), delay, **kwargs)

    def to_control(self, pade_order: int | None = None) -> Any:
        """Return a python-control ``TransferFunction``.

        The delay has no exact rational form. With ``pade_order=None`` a plant
        with a delay raises :class:`ModelError`; give an order to include a
        Pade approximation explicitly.

        Examples
        --------
        >>> Plant.from_string("2/(s+3)").to_control().dcgain()
        np.float64(0.6666666666666666)
        """
        import control

        sys = control.tf(self.num, self.den)
        if self.delay > 0:
            if pade_order is None:
                raise ModelError(
                    f"plant has a {self.delay:g} s delay, which python-control cannot hold "
                    "exactly; pass pade_order=N for a Pade approximation"
                )
            pnum, pden = control.pade(self.delay, pade_order)
            sys = sys * control.tf(pnum, pden)
        return sys

    # --------------------------------------------------------------- evaluation
    def freqresp(self, w: Any) -> np.ndarray:
        """Exact complex response ``G(j w)`` at frequencies ``w`` in rad/s.

        Examples
        --------
        >>> Plant.from_string("1/(s+1)", delay=0.5).freqresp([0.0, 1.0]).round(4)
        array([1.    +0.j    , 0.1991-0.6785j])
        """
        w = np.asarray(w, dtype=float)
        s = 1j * w
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.polyval(self.num, s) / np.polyval(self.den, s)
        if self.delay:
            g = g * np.exp(-s * self.delay)
        return g

    def rational_response(self, s: Any) -> np.ndarray:
        """Rational part ``num(s)/den(s)`` at complex ``s`` (no delay)."""
        s = np.asarray(s, dtype=complex)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.polyval(self.num, s) / np.polyval(self.den, s)

    def dc_gain(self) -> float:
        """Gain at ``s = 0`` (``inf`` with an integrator).

        Examples
        --------
        >>> Plant.from_string("1/(s*(s+1))").dc_gain()
        inf
        """
        d0 = self.den[-1]
        n0 = self.num[-1]
        if d0 == 0.0:
            return float("inf") if n0 != 0 else float("nan")
        return float(n0 / d0)

    def poles(self) -> np.ndarray:
        """Poles of the rational part.

        Examples
        --------
        >>> np.sort(Plant.from_string("1/((s+1)*(s+2))").poles().real)
        array([-2., -1.])
        """
        return np.roots(self.den)

    def zeros(self) -> np.ndarray:
        """Zeros of the rational part.

        Examples
        --------
        >>> Plant.from_string("(s+3)/((s+1)*(s+2))").zeros()
        array([-3.])
        """
        return np.roots(self.num) if self.num.size > 1 else np.array([])

    @property
    def relative_degree(self) -> int:
        """Denominator degree minus numerator degree."""
        return int(self.den.size - self.num.size)

    def scaled(self, gain: float, label: str | None = None) -> Plant:
        """Return the plant multiplied by ``gain`` (e.g. a battery-state variant).

        Examples
        --------
        >>> round(Plant.from_string("2/(s+1)").scaled(0.5).dc_gain(), 3)
        1.0
        """
        return Plant(self.num * gain, self.den, self.delay, self.input, self.output,
                     self.label if label is None else label)

    def with_delay(self, delay: float) -> Plant:
        """Return the same plant with its delay replaced by ``delay`` seconds.

        Examples
        --------
        >>> Plant.from_string("1/(s+1)").with_delay(0.02).delay
        0.02
        """
        return Plant(self.num, self.den, delay, self.input, self.output, self.label)

    def series(self, other: Plant) -> Plant:
        """Return ``self * other`` (delays add).

        Examples
        --------
        >>> Plant.from_string("1/(s+1)").series(Plant.from_string("2/(s+2)")).den
        array([1., 3., 2.])
        """
        return Plant(np.polymul(self.num, other.num), np.polymul(self.den, other.den),
                     self.delay + other.delay, other.input, self.output, self.label)

    # ------------------------------------------------------------------- output
    def to_string(self, digits: int = 4) -> str:
        """Factored text form that :func:`parse_tf` reads back.

        Examples
        --------
        >>> Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))").to_string()
        '23*(s+0.43)/((s+9.6)*(s+0.54))'
        """
        text = format_factored(self.num, self.den, digits)
        if self.delay:
            text = f"exp(-{self.delay:.{digits}g}*s)*{text}"
        return text

    def __str__(self) -> str:
        return self.to_string()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description.

        Examples
        --------
        >>> Plant.from_string("2/(s+1)").to_dict()["tf"]
        '2/(s+1)'
        """
        return {
            "tf": self.to_string(6),
            "num": self.num.tolist(),
            "den": self.den.tolist(),
            "delay": self.delay,
            "input": {"name": self.input.name, "unit": self.input.unit},
            "output": {"name": self.output.name, "unit": self.output.unit},
            "label": self.label,
        }
