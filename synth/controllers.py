"""Fixed-structure controllers: P, PI, PID with a derivative filter, lead-lag.

A :class:`ControllerType` knows its parameter names, units, default bounds
and transfer function; a :class:`Controller` is a type with values. On the
command line a controller is written ``P(3)``, ``PI(kp=1.2, ki=20)`` or
``PID(1, 2, 0.1, 0.01)`` (positional in the order of the parameters).
"""

from __future__ import annotations

import ast
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.polynomials import format_factored, trim

__all__ = [
    "CONTROLLER_TYPES",
    "RATIONAL",
    "Controller",
    "ControllerType",
    "Polys",
    "as_controller",
    "controller_type",
    "rational_order",
    "rational_type",
]

Polys = tuple[np.ndarray, np.ndarray]


@dataclass(frozen=True)
class ControllerType:
    """A controller structure.

    Attributes
    ----------
    name : str
        Name used in spec files and on the command line (``"P"``, ``"PI"``, ...).
    parameters : tuple of str
        Parameter names in positional order.
    units : dict
        Unit of each parameter, written with ``u`` for the plant input unit and
        ``y`` for the output unit (``"u/y"``, ``"u/(y*s)"``, ``"s"``, ``"rad/s"``).
    default_bounds : dict
        Bounds used when the spec gives none.
    formula : str
        Transfer function in words, for reports.
    """

    name: str
    parameters: tuple[str, ...]
    units: dict[str, str]
    default_bounds: dict[str, tuple[float, float]]
    formula: str
    build: Callable[[dict[str, float]], Polys] = field(repr=False, compare=False)
    positive: tuple[str, ...] = ()

    def tf(self, values: dict[str, float]) -> Polys:
        """Numerator and denominator for the given parameter values.

        Examples
        --------
        >>> num, den = CONTROLLER_TYPES["PI"].tf({"kp": 2.0, "ki": 5.0})
        >>> num.tolist(), den.tolist()
        ([2.0, 5.0], [1.0, 0.0])
        """
        for name in self.positive:
            if values[name] <= 0:
                raise ModelError(f"{self.name} parameter {name} must be > 0, got {values[name]:g}")
        num, den = self.build(values)
        return trim(np.asarray(num, float)), trim(np.asarray(den, float))


def _p(v: dict[str, float]) -> Polys:
    return np.array([v["kp"]]), np.array([1.0])


def _pi(v: dict[str, float]) -> Polys:
    return np.array([v["kp"], v["ki"]]), np.array([1.0, 0.0])


def _pid(v: dict[str, float]) -> Polys:
    kp, ki, kd, tf = v["kp"], v["ki"], v["kd"], v["tf"]
    num = np.array([kp * tf + kd, kp + ki * tf, ki])
    den = np.array([tf, 1.0, 0.0])
    return num, den


def _leadlag(v: dict[str, float]) -> Polys:
    return v["k"] * np.array([1.0, v["z"]]), np.array([1.0, v["p"]])


CONTROLLER_TYPES: dict[str, ControllerType] = {
    t.name: t
    for t in (
        ControllerType("P", ("kp",), {"kp": "u/y"}, {"kp": (0.0, 1e3)}, "C(s) = kp", _p),
        ControllerType(
            "PI", ("kp", "ki"), {"kp": "u/y", "ki": "u/(y*s)"},
            {"kp": (0.0, 1e3), "ki": (0.0, 1e4)}, "C(s) = kp + ki/s", _pi,
        ),
        ControllerType(
            "PID", ("kp", "ki", "kd", "tf"),
            {"kp": "u/y", "ki": "u/(y*s)", "kd": "u*s/y", "tf": "s"},
            {"kp": (0.0, 1e3), "ki": (0.0, 1e4), "kd": (0.0, 1e2), "tf": (1e-4, 1.0)},
            "C(s) = kp + ki/s + kd*s/(tf*s + 1)", _pid, positive=("tf",),
        ),
        ControllerType(
            "leadlag", ("k", "z", "p"), {"k": "u/y", "z": "rad/s", "p": "rad/s"},
            {"k": (0.0, 1e3), "z": (1e-3, 1e4), "p": (1e-3, 1e4)},
            "C(s) = k*(s + z)/(s + p)", _leadlag,
        ),
    )
}

RATIONAL = "rational"


def rational_type(m: int, n: int) -> ControllerType:
    """Fixed-order controller ``C = (b_m s^m + ... + b0)/(s^n + a_{n-1} s^{n-1} + ... + a0)``.

    ``m <= n`` (proper). Setting ``a0 = 0`` puts an integrator in the controller.

    Examples
    --------
    >>> t = rational_type(1, 2)
    >>> t.parameters
    ('b0', 'b1', 'a0', 'a1')
    >>> [c.tolist() for c in t.tf({"b0": 2.0, "b1": 1.0, "a0": 0.0, "a1": 10.0})]
    [[1.0, 2.0], [1.0, 10.0, 0.0]]
    """
    if not (0 <= m <= n) or n < 1:
        raise ModelError(f"rational controller order [{m}, {n}] must have 0 <= m <= n and n >= 1 (proper)")
    names = tuple(f"b{i}" for i in range(m + 1)) + tuple(f"a{i}" for i in range(n))

    def build(v: dict[str, float]) -> Polys:
        num = np.array([v[f"b{i}"] for i in range(m, -1, -1)])
        den = np.array([1.0] + [v[f"a{i}"] for i in range(n - 1, -1, -1)])
        return num, den

    units = {p: "" for p in names}
    bounds = {**{f"b{i}": (-1e4, 1e4) for i in range(m + 1)}, **{f"a{i}": (0.0, 1e4) for i in range(n)}}
    return ControllerType(RATIONAL, names, units, bounds,
                          f"C(s) = (b{m} s^{m} + ... + b0)/(s^{n} + a{n - 1} s^{n - 1} + ... + a0)", build)


def rational_order(parameters: Any) -> tuple[int, int]:
    """``(m, n)`` from rational parameter names ``b0..bm, a0..a(n-1)``.

    Examples
    --------
    >>> rational_order(["b0", "b1", "a0", "a1"])
    (1, 2)
    """
    names = list(parameters)
    bs = sorted(int(p[1:]) for p in names if p.startswith("b") and p[1:].isdigit())
    As = sorted(int(p[1:]) for p in names if p.startswith("a") and p[1:].isdigit())
    if not bs or not As or bs != list(range(len(bs))) or As != list(range(len(As))):
        raise ModelError("a rational controller needs coefficients b0..bm and a0..a(n-1)")
    return len(bs) - 1, len(As)


_ALIASES = {name.lower(): name for name in CONTROLLER_TYPES}
_ALIASES.update({"lead_lag": "leadlag", "lead-lag": "leadlag", "ll": "leadlag", RATIONAL: RATIONAL,
                 "fixed_order": RATIONAL})


def controller_type(name: str, order: tuple[int, int] | None = None) -> ControllerType:
    """Look a controller type up by name (case-insensitive); ``rational`` needs its ``order``.

    Examples
    --------
    >>> controller_type("pid").parameters
    ('kp', 'ki', 'kd', 'tf')
    """
    key = _ALIASES.get(str(name).lower())
    if key is None:
        raise ModelError(
            f"unknown controller type {name!r}; expected one of: {', '.join(CONTROLLER_TYPES)}, {RATIONAL}"
        )
    if key == RATIONAL:
        if order is None:
            raise ModelError("a rational controller needs its order [m, n]")
        return rational_type(*order)
    return CONTROLLER_TYPES[key]


@dataclass(frozen=True)
class Controller:
    """A controller of a given type with parameter values.

    Examples
    --------
    >>> C = Controller.from_string("PI(kp=1.2, ki=20)")
    >>> C.parameters
    {'kp': 1.2, 'ki': 20.0}
    >>> str(C)
    'PI(kp=1.2, ki=20)'
    >>> abs(C.freqresp([1.0])[0]).round(3)
    np.float64(20.036)
    """

    type: str
    parameters: dict[str, float]

    def __post_init__(self) -> None:
        key = _ALIASES.get(str(self.type).lower())
        order = rational_order(self.parameters) if key == RATIONAL else None
        ctype = controller_type(self.type, order)
        missing = [p for p in ctype.parameters if p not in self.parameters]
        extra = [p for p in self.parameters if p not in ctype.parameters]
        if extra:
            raise ModelError(
                f"{ctype.name} has no parameter {extra[0]!r}; its parameters are "
                f"{', '.join(ctype.parameters)}"
            )
        if missing:
            raise ModelError(f"{ctype.name} needs a value for {', '.join(missing)}")
        values = {}
        for p in ctype.parameters:
            v = self.parameters[p]
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
                raise ModelError(f"{ctype.name} parameter {p} must be a number, got {v!r}")
            if not np.isfinite(v):
                raise ModelError(f"{ctype.name} parameter {p} must be finite, got {v!r}")
            values[p] = float(v)
        object.__setattr__(self, "type", ctype.name)
        object.__setattr__(self, "parameters", values)
        num, den = ctype.tf(values)  # validates positivity constraints
        while num.size > 1 and den.size > 1 and num[-1] == 0.0 and den[-1] == 0.0:  # common factors s cancel
            num, den = num[:-1], den[:-1]
        num.setflags(write=False)  # shared by every caller of tf(): an in-place change is an error, not a stale copy
        den.setflags(write=False)
        object.__setattr__(self, "_tf", (num, den))  # searches and maps ask for a controller's polynomials often

    @property
    def kind(self) -> ControllerType:
        """The :class:`ControllerType`."""
        if self.type == RATIONAL:
            return rational_type(*rational_order(self.parameters))
        return CONTROLLER_TYPES[self.type]

    @classmethod
    def from_string(cls, text: str) -> Controller:
        """Parse ``P(3)``, ``PI(kp=1.2, ki=20)``, ``PID(1, 2, 0.1, 0.01)``.

        Examples
        --------
        >>> Controller.from_string("leadlag(k=2, z=1, p=10)").parameters["p"]
        10.0
        """
        if not isinstance(text, str) or not text.strip():
            raise ModelError("empty controller; write e.g. 'P(3)' or 'PI(kp=1.2, ki=20)'")
        try:
            node = ast.parse(text.strip(), mode="eval").body
        except SyntaxError:
            raise ModelError(f"cannot parse controller {text!r}; write e.g. 'PI(kp=1.2, ki=20)'") from None
        if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Name):
            raise ModelError(f"cannot parse controller {text!r}; write e.g. 'PI(kp=1.2, ki=20)'")
        if _ALIASES.get(node.func.id.lower()) == RATIONAL:
            if node.args:
                raise ModelError(f"controller {text!r}: give rational coefficients by name, "
                                 "e.g. rational(b0=2, b1=1, a0=0, a1=10)")
            values = {kw.arg: _number(kw.value, text) for kw in node.keywords}
            try:
                return cls(RATIONAL, values)
            except ModelError as exc:
                raise ModelError(f"controller {text!r}: {exc.message}") from None
        ctype = controller_type(node.func.id)
        if len(node.args) > len(ctype.parameters):
            raise ModelError(
                f"{ctype.name} takes {len(ctype.parameters)} parameter(s) "
                f"({', '.join(ctype.parameters)}), got {len(node.args)}"
            )
        values: dict[str, Any] = {}
        for name, arg in zip(ctype.parameters, node.args):
            values[name] = _number(arg, text)
        for kw in node.keywords:
            if kw.arg is None:
                raise ModelError(f"cannot parse controller {text!r}")
            if kw.arg in values:
                raise ModelError(f"controller {text!r} gives {kw.arg} twice")
            values[kw.arg] = _number(kw.value, text)
        try:
            return cls(ctype.name, values)
        except ModelError as exc:
            raise ModelError(f"controller {text!r}: {exc.message}") from None

    def tf(self) -> Polys:
        """Numerator and denominator polynomials, with exact common factors ``s`` cancelled
        (``PI(kp, 0)`` is the gain ``kp``, not ``kp s / s``).

        Examples
        --------
        >>> Controller("P", {"kp": 3}).tf()
        (array([3.]), array([1.]))
        >>> Controller("PI", {"kp": 2, "ki": 0}).tf()
        (array([2.]), array([1.]))
        """
        return self._tf  # type: ignore[attr-defined]  # made once, by __post_init__

    def freqresp(self, w: Any) -> np.ndarray:
        """Complex response ``C(j w)``.

        Examples
        --------
        >>> Controller("P", {"kp": 3}).freqresp([1.0, 10.0])
        array([3.+0.j, 3.+0.j])
        """
        num, den = self.tf()
        s = 1j * np.asarray(w, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.polyval(num, s) / np.polyval(den, s)

    def dc_gain(self) -> float:
        """``C(0)``; ``inf`` with integral action.

        Examples
        --------
        >>> Controller.from_string("PI(1, 2)").dc_gain()
        inf
        """
        num, den = self.tf()
        if not np.any(num):
            return 0.0
        while num.size > 1 and den.size > 1 and num[-1] == 0.0 and den[-1] == 0.0:
            num, den = num[:-1], den[:-1]  # cancel common factors s
        if den[-1] == 0.0:
            return float("inf")
        return float(num[-1] / den[-1])

    def to_control(self) -> Any:
        """The controller as a python-control ``TransferFunction`` (exact: a controller has no delay).

        Returns
        -------
        control.TransferFunction
            ``num/den`` of :meth:`tf`.

        Examples
        --------
        >>> C = Controller.from_string("PI(kp=2, ki=4)").to_control()
        >>> C.num[0][0].tolist(), C.den[0][0].tolist()
        ([2.0, 4.0], [1.0, 0.0])
        >>> abs(C(2j)).round(4)
        np.float64(2.8284)
        """
        import control

        num, den = self.tf()
        return control.tf(num, den)

    def with_parameters(self, **values: float) -> Controller:
        """Copy with some parameters replaced.

        Examples
        --------
        >>> Controller("P", {"kp": 3}).with_parameters(kp=4.0).parameters
        {'kp': 4.0}
        """
        return Controller(self.type, {**self.parameters, **values})

    def transfer_function_text(self, digits: int = 4) -> str:
        """Factored transfer function text.

        Examples
        --------
        >>> Controller.from_string("PI(kp=2, ki=4)").transfer_function_text()
        '2*(s+2)/s'
        """
        num, den = self.tf()
        return format_factored(num, den, digits)

    def __str__(self) -> str:
        args = ", ".join(f"{k}={v:.6g}" for k, v in self.parameters.items())
        return f"{self.type}({args})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict ``{"type": ..., "parameters": {...}, "tf": ...}``.

        Examples
        --------
        >>> Controller("P", {"kp": 3}).to_dict()["parameters"]
        {'kp': 3.0}
        """
        return {
            "type": self.type,
            "parameters": dict(self.parameters),
            "units": dict(self.kind.units),
            "tf": self.transfer_function_text(6),
            "text": str(self),
        }


def as_controller(controller: Controller | str) -> Controller:
    """A :class:`Controller` from a Controller or its text (``"P(3)"``, ``"PI(kp=1.2, ki=20)"``).

    Parameters
    ----------
    controller : Controller or str
        The controller, or text that :meth:`Controller.from_string` reads.

    Returns
    -------
    Controller

    Raises
    ------
    ModelError
        Unreadable text or another type.

    Examples
    --------
    >>> as_controller("PI(1.2, 20)").parameters
    {'kp': 1.2, 'ki': 20.0}
    >>> as_controller(3.0)
    Traceback (most recent call last):
    ...
    synth.errors.ModelError: cannot make a controller from a float; give a Controller or text like 'P(3)' ...
    """
    if isinstance(controller, Controller):
        return controller
    if isinstance(controller, str):
        return Controller.from_string(controller)
    raise ModelError(f"cannot make a controller from a {type(controller).__name__}; give a Controller "
                     "or text like 'P(3)' or 'PI(kp=1.2, ki=20)'")


def _number(node: ast.AST, text: str) -> float:
    try:
        value = ast.literal_eval(node)
    except ValueError:
        raise ModelError(f"controller {text!r}: parameters must be numbers") from None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ModelError(f"controller {text!r}: parameters must be numbers")
    return float(value)
