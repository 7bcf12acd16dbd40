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

__all__ = ["Plant", "Signal", "as_plant"]


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
    def from_control(
        cls,
        sys: Any,
        delay: float = 0.0,
        input: Signal | None = None,
        output: Signal | None = None,
        label: str = "",
    ) -> Plant:
        """Build a plant from a python-control ``TransferFunction`` or ``StateSpace``.

        This is how a python-control model enters synth: ``Plant.from_control(sys, delay=...)``,
        or pass ``sys`` straight to :class:`synth.loop.Loop` (which calls :func:`as_plant`).

        Parameters
        ----------
        sys : control.TransferFunction or control.StateSpace
            A continuous-time, single-input single-output, proper model.
        delay : float
            Exact input-output delay in seconds (python-control has no exact delay).
        input, output : Signal, optional
            Names and units of the input and output.
        label : str
            Free text used in reports.

        Returns
        -------
        Plant

        Raises
        ------
        ModelError
            A discrete-time or multi-input/multi-output model, another type, a negative delay.

        Examples
        --------
        >>> import control
        >>> G = Plant.from_control(control.tf([2.0], [1.0, 3.0]), delay=0.1)
        >>> G.to_string(), G.delay
        ('exp(-0.1*s)*2/(s+3)', 0.1)
        >>> Plant.from_control(control.ss([[-3.0]], [[1.0]], [[2.0]], [[0.0]])).to_string()
        '2/(s+3)'
        >>> Plant.from_control(control.tf([1.0], [1.0, -0.5], 0.01))
        Traceback (most recent call last):
        ...
        synth.errors.ModelError: a discrete-time model (dt = 0.01) cannot be a plant; give a continuous-time one
        """
        import control

        if not isinstance(sys, control.TransferFunction | control.StateSpace):
            raise ModelError(f"expected a python-control TransferFunction or StateSpace, got {type(sys).__name__}")
        if sys.ninputs != 1 or sys.noutputs != 1:
            raise ModelError(f"only single-input single-output models can be a plant; this one has "
                             f"{sys.ninputs} input(s) and {sys.noutputs} output(s)")
        if control.isdtime(sys, strict=True):
            raise ModelError(f"a discrete-time model (dt = {sys.dt}) cannot be a plant; give a continuous-time one")
        if isinstance(sys, control.StateSpace):
            sys = control.ss2tf(sys)
        num = np.asarray(sys.num[0][0], dtype=float)
        den = np.asarray(sys.den[0][0], dtype=float)
        return cls(num, den, delay, input or Signal("u", ""), output or Signal("y", ""), label)

    def to_control(self, pade_order: int | None = None) -> Any:
        """Return a python-control ``TransferFunction``.

        The delay has no exact rational form. A plant without a delay is returned exactly; with a
        delay, ``pade_order=None`` raises :class:`ModelError` (the delay is never dropped silently)
        and ``pade_order=N`` multiplies by ``control.pade(delay, N)``.

        Parameters
        ----------
        pade_order : int, optional
            Order of the Pade approximation of the delay (needed when there is one).

        Returns
        -------
        control.TransferFunction

        Raises
        ------
        ModelError
            A delay without ``pade_order``, or an order below 1.

        Examples
        --------
        >>> Plant.from_string("2/(s+3)").to_control().dcgain()
        np.float64(0.6666666666666666)
        >>> G = Plant.from_string("2/(s+3)", delay=0.1)
        >>> G.to_control()
        Traceback (most recent call last):
        ...
        synth.errors.ModelError: plant has a 0.1 s delay, which python-control cannot hold exactly; pass pade_order=N ...
        >>> G.to_control(pade_order=3).den[0][0].size  # 1 plant pole + 3 Pade poles
        5
        """
        import control

        sys = control.tf(self.num, self.den)
        if self.delay > 0:
            if pade_order is None:
                raise ModelError(
                    f"plant has a {self.delay:g} s delay, which python-control cannot hold "
                    "exactly; pass pade_order=N for a Pade approximation"
                )
            if isinstance(pade_order, bool) or not isinstance(pade_order, int | np.integer) or pade_order < 1:
                raise ModelError(f"pade_order must be a whole number >= 1, got {pade_order!r}")
            pnum, pden = control.pade(self.delay, int(pade_order))
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

    def settling_time(self, time_constants: float) -> float:
        """``time_constants`` time constants of the slowest pole, plus the delay [s]; inf if a pole is on or
        right of the imaginary axis (the model never forgets its state), the delay for a static gain.

        Examples
        --------
        >>> Plant.from_string("1/(0.5*s+1)", delay=0.1).settling_time(20), Plant.from_string("1/s").settling_time(5)
        (10.1, inf)
        """
        poles = self.poles()
        if poles.size == 0:
            return float(self.delay)
        slowest = float(np.min(-poles.real))
        return round(time_constants / slowest + float(self.delay), 12) if slowest > 0 else float("inf")

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


def as_plant(model: Any, delay: float = 0.0) -> Plant:
    """A :class:`Plant` from what a user holds: a Plant, transfer-function text, a python-control
    ``TransferFunction``/``StateSpace`` or a ``(num, den)`` pair.

    Parameters
    ----------
    model : Plant, str, control.TransferFunction, control.StateSpace or (num, den)
        The plant. Text is read by :func:`synth.tfparse.parse_tf` (``exp(-0.02*s)`` is an exact delay).
    delay : float
        Exact delay in seconds added to the model's own (python-control models have none).

    Returns
    -------
    Plant

    Raises
    ------
    ModelError
        A model of another type, or one :meth:`Plant.from_control` or :meth:`Plant.from_string` refuses.

    Examples
    --------
    >>> import control
    >>> as_plant(control.tf([23.0], [1.0, 10.0]), delay=0.02).to_string()
    'exp(-0.02*s)*23/(s+10)'
    >>> as_plant("23/(s+10)").dc_gain()
    2.3
    >>> as_plant(([23.0], [1.0, 10.0])).poles()
    array([-10.])
    >>> as_plant(2.0)
    Traceback (most recent call last):
    ...
    synth.errors.ModelError: cannot make a plant from a float; give a Plant, transfer-function text like '23/(s+10)', ...
    """
    if isinstance(model, Plant):
        return model if not delay else model.with_delay(model.delay + float(delay))
    if isinstance(model, str):
        return Plant.from_string(model, delay)
    if isinstance(model, tuple) and len(model) == 2:
        return Plant(np.atleast_1d(np.asarray(model[0], dtype=float)), np.atleast_1d(np.asarray(model[1], dtype=float)),
                     delay)
    if type(model).__module__.split(".")[0] == "control":
        return Plant.from_control(model, delay)
    raise ModelError(f"cannot make a plant from a {type(model).__name__}; give a Plant, transfer-function text "
                     "like '23/(s+10)', a python-control TransferFunction or StateSpace, or (num, den)")
