"""Parametric transfer-function structures written as formulas, e.g. ``k*(s+z)/((s+p1)*(s+p2))``.

Every name other than ``s`` (the Laplace variable) and ``exp`` is a parameter.
The grammar is the one of :func:`synth.tfparse.parse_tf` (numbers, ``+ - * /``,
integer powers ``^`` or ``**``, parentheses, implicit multiplication such as
``2s``, ``2k`` or ``(s+a)(s+b)``; a name directly before a parenthesis is a
function call, so write ``k*(s+z)``) with parameter names added, and an
optional delay factor ``exp(-Td*s)`` (a parameter) or ``exp(-0.02*s)`` (a
number) multiplying the rational part.

The formula is parsed once into a syntax tree; evaluating that tree with
numbers gives numpy coefficients, evaluating it with casadi symbols gives
casadi expressions of the same coefficients, so a fit can differentiate
through them. Coefficients are in descending powers of ``s``.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.plant import Plant

__all__ = ["Structure", "parse_structure"]

_TOKEN = re.compile(r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<name>[A-Za-z_]\w*)|(?P<op>\*\*|[-+*/^()]))")
_RESERVED = {"s", "exp"}


def _tokenize(text: str) -> str:
    """Python source for ``text``: ``^`` becomes ``**`` and implicit products get a ``*``."""
    tokens: list[tuple[str, str]] = []
    pos = 0
    text = text.strip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            raise ModelError(f"structure {text!r}: unexpected character {text[pos:].strip()[:1]!r} at position {pos}")
        kind = m.lastgroup or "op"
        value = m.group(kind)
        tokens.append((kind, "**" if value == "^" else value))
        pos = m.end()
    out: list[str] = []
    for i, (kind, value) in enumerate(tokens):
        if i:
            pkind, pvalue = tokens[i - 1]
            ends_operand = pkind in ("num", "name") or pvalue == ")"
            starts_operand = kind in ("num", "name") or value == "("
            if pkind == "name" and pvalue != "exp" and value == "(":
                raise ModelError(f"structure {text!r}: unknown function {pvalue!r}; only exp(-tau*s) is a function, "
                                 f"write {pvalue}*(...) for a product")
            if ends_operand and starts_operand and not (pkind == "name" and value == "("):
                out.append("*")
        out.append(value)
    return "".join(out)


class _Rational:
    """``num(s)/den(s) * exp(-delay s)`` with coefficients of any numeric type (float or casadi)."""

    __slots__ = ("delay", "den", "num")

    def __init__(self, num: list[Any], den: list[Any], delay: Any = None) -> None:
        self.num, self.den, self.delay = num, den, delay

    @staticmethod
    def const(value: Any) -> _Rational:
        return _Rational([value], [1.0])

    def is_const(self) -> bool:
        return len(self.num) == 1 and len(self.den) == 1 and self.delay is None

    def _no_delay(self, what: str) -> None:
        if self.delay is not None:
            raise ModelError(f"exp(-tau*s) may only multiply the whole transfer function, not appear in a {what}")


def _pmul(a: list[Any], b: list[Any]) -> list[Any]:
    out: list[Any] = [0.0] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            out[i + j] = out[i + j] + x * y
    return out


def _padd(a: list[Any], b: list[Any]) -> list[Any]:
    n = max(len(a), len(b))
    a = [0.0] * (n - len(a)) + list(a)
    b = [0.0] * (n - len(b)) + list(b)
    return [x + y for x, y in zip(a, b)]


def _eval(node: ast.AST, env: Mapping[str, Any], delay_names: list[str]) -> _Rational:
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ModelError(f"unexpected constant {node.value!r}")
        return _Rational.const(float(node.value))
    if isinstance(node, ast.Name):
        if node.id == "s":
            return _Rational([1.0, 0.0], [1.0])
        if node.id == "exp":
            raise ModelError("exp must be called, e.g. exp(-Td*s)")
        return _Rational.const(env[node.id])
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = _eval(node.operand, env, delay_names)
        if isinstance(node.op, ast.UAdd):
            return inner
        return _Rational([-c for c in inner.num], inner.den, inner.delay)
    if isinstance(node, ast.BinOp):
        left = _eval(node.left, env, delay_names)
        if isinstance(node.op, ast.Pow):
            if not isinstance(node.right, ast.Constant) and not (
                    isinstance(node.right, ast.UnaryOp) and isinstance(node.right.operand, ast.Constant)):
                raise ModelError("exponents must be integer numbers, e.g. (T*s+1)^2")
            exponent = _eval(node.right, env, delay_names).num[0]
            if float(exponent) != int(exponent):
                raise ModelError(f"non-integer power {exponent:g}")
            left._no_delay("power")
            k = int(exponent)
            base = left if k >= 0 else _Rational(left.den, left.num)
            num, den = [1.0], [1.0]
            for _ in range(abs(k)):
                num, den = _pmul(num, base.num), _pmul(den, base.den)
            return _Rational(num, den)
        right = _eval(node.right, env, delay_names)
        if isinstance(node.op, (ast.Add, ast.Sub)):
            left._no_delay("sum")
            right._no_delay("sum")
            rnum = right.num if isinstance(node.op, ast.Add) else [-c for c in right.num]
            if len(left.den) == 1 and len(right.den) == 1 and _same(left.den[0], right.den[0]):
                return _Rational(_padd(left.num, rnum), left.den)
            return _Rational(_padd(_pmul(left.num, right.den), _pmul(rnum, left.den)), _pmul(left.den, right.den))
        if isinstance(node.op, ast.Mult):
            if left.delay is not None and right.delay is not None:
                raise ModelError("only one delay factor exp(-tau*s) is allowed")
            return _Rational(_pmul(left.num, right.num), _pmul(left.den, right.den),
                             left.delay if left.delay is not None else right.delay)
        if isinstance(node.op, ast.Div):
            right._no_delay("divisor (that would be a predictor)")
            return _Rational(_pmul(left.num, right.den), _pmul(left.den, right.num), left.delay)
        raise ModelError(f"operator {type(node.op).__name__} is not allowed")
    if isinstance(node, ast.Call):
        name = getattr(node.func, "id", "?")
        if name != "exp":
            raise ModelError(f"unknown function {name!r}; only exp(-tau*s) is allowed")
        if len(node.args) != 1 or node.keywords:
            raise ModelError("exp takes one argument, e.g. exp(-Td*s)")
        return _Rational([1.0], [1.0], _delay_of(node.args[0], delay_names))
    raise ModelError(f"unexpected syntax {ast.unparse(node)!r}")


def _same(a: Any, b: Any) -> bool:
    return isinstance(a, float) and isinstance(b, float) and a == b


def _delay_of(arg: ast.AST, delay_names: list[str]) -> Any:
    """The delay in ``exp(arg)``: ``arg`` must be ``-Td*s`` (one parameter) or ``-0.02*s`` (numbers)."""
    msg = "exp(...) must be a delay exp(-Td*s) with one parameter Td or a number, e.g. exp(-0.02*s)"
    sign, factors = 1.0, []
    stack = [arg]
    while stack:
        node = stack.pop()
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            sign *= -1.0 if isinstance(node.op, ast.USub) else 1.0
            stack.append(node.operand)
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult):
            stack.extend([node.left, node.right])
        else:
            factors.append(node)
    s_count = sum(isinstance(f, ast.Name) and f.id == "s" for f in factors)
    names = [f.id for f in factors if isinstance(f, ast.Name) and f.id not in _RESERVED]
    numbers = [f.value for f in factors if isinstance(f, ast.Constant) and isinstance(f.value, (int, float))
               and not isinstance(f.value, bool)]
    if s_count != 1 or len(names) + len(numbers) + 1 != len(factors) or len(names) > 1:
        raise ModelError(msg)
    value = sign * float(np.prod(numbers)) if numbers else sign
    if names:
        if value != -1.0:
            raise ModelError(msg)
        delay_names.append(names[0])
        return names[0]
    if value > 0:
        raise ModelError("a delay exp(-tau*s) needs tau >= 0 (exp(+tau*s) is a predictor)")
    return -value


def _names(tree: ast.AST) -> list[str]:
    seen: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id not in _RESERVED and node.id not in seen:
            seen.append(node.id)
    # ast.walk is breadth-first; order the names by where they appear in the text instead
    return sorted(seen, key=lambda n: min(getattr(x, "col_offset", 0) for x in ast.walk(tree)
                                          if isinstance(x, ast.Name) and x.id == n))


@dataclass(frozen=True, eq=False)
class Structure:
    """A transfer function whose coefficients depend on named parameters.

    Build it with :func:`parse_structure`. ``parameters`` are the names in the
    rational part, in the order they first appear in the formula; ``delay`` is
    ``None`` (no delay factor), a number (a fixed ``exp(-0.02*s)``) or the name
    of the delay parameter (``exp(-Td*s)``), which is not in ``parameters``.

    Examples
    --------
    >>> st = parse_structure("k*(s+z)/((s+p1)*(s+p2))")
    >>> st.parameters, st.num_degree, st.den_degree
    (('k', 'z', 'p1', 'p2'), 1, 2)
    >>> num, den = st.coefficients([23, 0.43, 9.6, 0.54])
    >>> num.tolist(), den.round(3).tolist()
    ([23.0, 9.89], [1.0, 10.14, 5.184])
    """

    formula: str
    parameters: tuple[str, ...]
    delay: str | float | None
    num_degree: int
    den_degree: int
    _tree: ast.Expression

    @property
    def delay_parameter(self) -> str | None:
        """Name of the delay parameter (``Td`` in ``exp(-Td*s)``), or ``None``."""
        return self.delay if isinstance(self.delay, str) else None

    def _env(self, theta: Sequence[Any] | Mapping[str, Any]) -> dict[str, Any]:
        if isinstance(theta, Mapping):
            missing = [p for p in self.parameters if p not in theta]
            if missing:
                raise ModelError(f"structure {self.formula!r}: no value for parameter(s) {', '.join(missing)}")
            env = {p: theta[p] for p in self.parameters}
        else:
            if len(theta) != len(self.parameters):
                raise ModelError(f"structure {self.formula!r} has {len(self.parameters)} parameters "
                                 f"({', '.join(self.parameters)}), got {len(theta)} values")
            env = dict(zip(self.parameters, theta))
        if self.delay_parameter:
            env.setdefault(self.delay_parameter, 0.0)
        return env

    def _evaluate(self, theta: Sequence[Any] | Mapping[str, Any], convert: Callable[[Any], Any]) -> tuple[list, list]:
        env = {k: convert(v) for k, v in self._env(theta).items()}
        r = _eval(self._tree.body, env, [])
        num = r.num[len(r.num) - self.num_degree - 1:]
        den = r.den[len(r.den) - self.den_degree - 1:]
        return num, den

    def coefficients(self, theta: Sequence[float] | Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
        """Numerator and denominator coefficients (descending powers, not normalized) at ``theta``.

        Examples
        --------
        >>> parse_structure("K/(T1*s+1)^2").coefficients({"K": 2.0, "T1": 0.5})[1].tolist()
        [0.25, 1.0, 1.0]
        """
        num, den = self._evaluate(theta, float)
        return np.asarray(num, float), np.asarray(den, float)

    def casadi_coefficients(self, theta: Any) -> tuple[list[Any], list[Any]]:
        """The same coefficients as casadi expressions of a symbolic parameter vector ``theta``.

        Examples
        --------
        >>> import casadi as ca
        >>> th = ca.SX.sym("th", 2)
        >>> num, den = parse_structure("K/(T1*s+1)").casadi_coefficients(th)
        >>> f = ca.Function("f", [th], [ca.vertcat(*den)])
        >>> f([2.0, 0.5]).full().ravel().tolist()
        [0.5, 1.0]
        """
        n = len(self.parameters)
        values = [theta[i] for i in range(n)]
        return self._evaluate(values, lambda v: v)

    def plant(self, theta: Sequence[float] | Mapping[str, float], delay: float | None = None, **kwargs: Any) -> Plant:
        """The :class:`~synth.plant.Plant` at ``theta``.

        ``delay`` defaults to the formula's fixed delay (0 without one); it is
        required when the formula has a delay parameter, unless ``theta`` is a
        mapping holding it.

        Examples
        --------
        >>> G = parse_structure("K*exp(-Td*s)/(T1*s+1)^2").plant({"K": 245.5, "T1": 0.147, "Td": 0.035})
        >>> round(G.dc_gain(), 6), G.delay
        (245.5, 0.035)
        """
        if delay is None:
            if isinstance(self.delay, float):
                delay = self.delay
            elif self.delay_parameter and isinstance(theta, Mapping) and self.delay_parameter in theta:
                delay = float(theta[self.delay_parameter])
            elif self.delay_parameter:
                raise ModelError(f"structure {self.formula!r}: give a value for the delay {self.delay_parameter}")
            else:
                delay = 0.0
        num, den = self.coefficients(theta)
        if not np.any(den):
            raise ModelError(f"structure {self.formula!r}: the denominator vanishes at these parameter values")
        return Plant(num, den, float(delay), **kwargs)

    def normalized_coefficients(self, theta: Sequence[float]) -> np.ndarray:
        """Numerator then denominator coefficients at ``theta``, divided by the denominator's leading nonzero one:
        equal for two parameter vectors exactly when they give the same transfer function.

        Examples
        --------
        >>> parse_structure("k/(T*s+1)").normalized_coefficients([2.0, 0.5]).tolist()
        [4.0, 1.0, 2.0]
        """
        num, den = self.coefficients(np.asarray(theta, float))
        lead = den[np.flatnonzero(den)[0]] if np.any(den) else 1.0
        return np.r_[np.asarray(num, float), np.asarray(den, float)] / lead

    def sign_symmetries(self) -> list[tuple[str, ...]]:
        """Sets of parameters whose joint change of sign leaves the transfer function unchanged.

        In ``k*w^2/(s^2+2*z*w*s+w^2)``, ``(-w, -z)`` gives the same plant as ``(w, z)``: a fit may end on either.
        Found by evaluating the coefficients with signs flipped at random values (a coincidence is not taken for a
        symmetry); structures with more than 10 parameters are not searched.

        Examples
        --------
        >>> parse_structure("k*w^2/(s^2+2*z*w*s+w^2)").sign_symmetries()
        [('w', 'z')]
        >>> parse_structure("k*(s+z)/((s+p1)*(s+p2))").sign_symmetries()
        []
        """
        return list(_sign_symmetries(self.formula))

    def canonical_signs(self, theta: Sequence[float]) -> tuple[np.ndarray, tuple[str, ...]]:
        """The equivalent parameters (:meth:`sign_symmetries`) with the fewest negative values, ties going to the
        one whose first negative value comes latest (``w > 0`` before ``z > 0``), and the names whose sign changed.

        Examples
        --------
        >>> st = parse_structure("k*w^2/(s^2+2*z*w*s+w^2)")
        >>> theta, flipped = st.canonical_signs([1.0, -445.0, -0.05])
        >>> theta.tolist(), flipped
        ([1.0, 445.0, 0.05], ('w', 'z'))
        >>> st.canonical_signs([1.0, -2.0, 0.3])[0].tolist()
        [1.0, 2.0, -0.3]
        """
        theta = np.asarray(theta, float).copy()
        index = {n: i for i, n in enumerate(self.parameters)}

        def key(names: tuple[str, ...]) -> tuple[int, tuple[bool, ...]]:
            flipped = theta.copy()
            flipped[[index[n] for n in names]] *= -1.0
            negative = tuple(bool(v < 0) for v in flipped)
            return sum(negative), negative

        best = min([(), *self.sign_symmetries()], key=key)
        theta[[index[n] for n in best]] *= -1.0
        return theta, tuple(best)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description.

        Examples
        --------
        >>> parse_structure("k/(s+p)").to_dict()["parameters"]
        ['k', 'p']
        """
        return {"formula": self.formula, "parameters": list(self.parameters), "delay": self.delay,
                "num_degree": self.num_degree, "den_degree": self.den_degree}


def parse_structure(formula: str) -> Structure:
    """Parse a parametric transfer-function formula.

    Parameters
    ----------
    formula : str
        For example ``"k*(s+z)/((s+p1)*(s+p2))"``, ``"K/(T1*s+1)^2"`` or
        ``"K*exp(-Td*s)/(T1*s+1)^2"``. Names other than ``s`` and ``exp`` are
        parameters; ``delay`` is reserved for the delay parameter.

    Returns
    -------
    Structure

    Raises
    ------
    ModelError
        If the formula cannot be parsed, has no parameters, is improper (more
        zeros than poles for generic parameter values), or uses the delay
        parameter in the rational part too.

    Notes
    -----
    Degrees are structural: they are found by evaluating the coefficients at
    two generic parameter points, so a leading coefficient that vanishes for
    every parameter value (``(s+a) - s``) does not count. A sum of fractions is
    put over the product of the denominators without cancelling common
    factors; write structures as products.

    Examples
    --------
    >>> parse_structure("K*exp(-Td*s)/(T1 s+1)^2").parameters, parse_structure("K*exp(-Td*s)/(T1*s+1)^2").delay
    (('K', 'T1'), 'Td')
    >>> parse_structure("k*s^2/(s+p)")
    Traceback (most recent call last):
    synth.errors.ModelError: structure 'k*s^2/(s+p)' is improper (numerator degree 2 > denominator degree 1)
    >>> parse_structure("(s+1)/(s+2)")
    Traceback (most recent call last):
    synth.errors.ModelError: structure '(s+1)/(s+2)' has no parameters; name at least one, e.g. k/(s+p)
    """
    if not isinstance(formula, str) or not formula.strip():
        raise ModelError("empty structure; write a formula in s with named parameters, e.g. k/(s+p)")
    try:
        source = _tokenize(formula)
    except ModelError as exc:
        raise ModelError(exc.message) from None
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        raise ModelError(f"cannot parse structure {formula!r}: {exc.msg}") from None
    names = _names(tree)
    delay_names: list[str] = []
    rng = np.random.default_rng(12345)
    points = [{n: float(v) for n, v in zip(names, rng.uniform(0.5, 2.0, len(names)))} for _ in range(2)]
    try:
        evaluated = [_eval(tree.body, p, delay_names if i == 0 else []) for i, p in enumerate(points)]
    except ModelError as exc:
        raise ModelError(f"structure {formula!r}: {exc.message}") from None
    except ZeroDivisionError:
        raise ModelError(f"structure {formula!r}: division by zero") from None
    delay: str | float | None = evaluated[0].delay
    params = [n for n in names if n not in delay_names]
    if delay_names and delay_names[0] in _rational_names(tree, delay_names[0]):
        raise ModelError(f"structure {formula!r}: the delay parameter {delay_names[0]!r} also appears in the "
                         "rational part; use a separate name")
    if "delay" in params:
        raise ModelError(f"structure {formula!r}: 'delay' is reserved for the delay; use it only as exp(-delay*s)")
    if not params:
        raise ModelError(f"structure {formula!r} has no parameters; name at least one, e.g. k/(s+p)")

    def degree(coeffs: list[list[float]]) -> int:
        arr = [np.asarray(c, float) for c in coeffs]
        scale = max(float(np.max(np.abs(a))) for a in arr)
        lead = next((i for i in range(arr[0].size) if any(abs(a[i]) > 1e-12 * scale for a in arr)), arr[0].size - 1)
        return arr[0].size - 1 - lead

    nd = degree([e.num for e in evaluated])
    dd = degree([e.den for e in evaluated])
    if all(not np.any(np.asarray(e.den, float)) for e in evaluated):
        raise ModelError(f"structure {formula!r} has a zero denominator")
    if nd > dd:
        raise ModelError(f"structure {formula!r} is improper (numerator degree {nd} > denominator degree {dd})")
    return Structure(formula.strip(), tuple(params), delay, nd, dd, tree)


@lru_cache(maxsize=256)
def _sign_symmetries(formula: str) -> tuple[tuple[str, ...], ...]:
    """Non-empty parameter sets whose joint sign flip leaves the normalized coefficients of ``formula`` unchanged."""
    st = parse_structure(formula)
    names = st.parameters
    if len(names) > 10:
        return ()
    theta = np.random.default_rng(20261205).uniform(0.5, 2.0, len(names))
    base = st.normalized_coefficients(theta)
    found = []
    for mask in range(1, 2 ** len(names)):
        signs = np.array([-1.0 if mask >> i & 1 else 1.0 for i in range(len(names))])
        flipped = st.normalized_coefficients(signs * theta)
        if np.allclose(flipped, base, rtol=1e-10, atol=1e-12 * float(np.max(np.abs(base)))):
            found.append(tuple(n for i, n in enumerate(names) if mask >> i & 1))
    return tuple(sorted(found, key=lambda g: (len(g), [names.index(n) for n in g])))


def _rational_names(tree: ast.AST, delay_name: str) -> set[str]:
    """Names used outside ``exp(...)`` calls."""
    inside: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            inside.update(id(x) for x in ast.walk(node))
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and id(n) not in inside}
