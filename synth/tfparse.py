"""Parse transfer-function strings into a rational function times a delay.

Accepted: numbers, the Laplace variable ``s``, ``+ - * /``, powers written
``^`` or ``**`` with integer exponents, parentheses, implicit multiplication
(``2s``, ``(s+1)(s+2)``, ``3(s+1)``) and delays ``exp(-tau*s)``. The result is
``num(s)/den(s) * exp(-delay*s)`` with polynomial coefficients in descending
powers of ``s``.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from synth.errors import ModelError

__all__ = ["ParsedTF", "parse_tf"]

_ALLOWED_FUNCS = {"exp"}


@dataclass(frozen=True)
class ParsedTF:
    """A parsed transfer function ``num(s)/den(s) * exp(-delay*s)``.

    Coefficients are in descending powers of ``s``; ``den`` is monic.
    """

    num: tuple[float, ...]
    den: tuple[float, ...]
    delay: float


class _Term:
    """A rational function of ``s`` times ``exp(-delay*s)`` during parsing."""

    __slots__ = ("delay", "den", "num")

    def __init__(self, num: np.ndarray, den: np.ndarray, delay: float = 0.0) -> None:
        self.num = _trim(np.asarray(num, dtype=float))
        self.den = _trim(np.asarray(den, dtype=float))
        self.delay = float(delay)

    @classmethod
    def constant(cls, value: float) -> _Term:
        return cls(np.array([value]), np.array([1.0]))

    def is_constant(self) -> bool:
        return self.num.size == 1 and self.den.size == 1 and self.delay == 0.0

    def value(self) -> float:
        return float(self.num[0] / self.den[0])

    def __add__(self, other: _Term) -> _Term:
        if not np.isclose(self.delay, other.delay, rtol=1e-12, atol=1e-15):
            if _is_zero(self.num):
                return other
            if _is_zero(other.num):
                return self
            raise ModelError(
                "a sum of terms with different delays is not a rational transfer "
                "function times one delay; factor the delay out, e.g. exp(-0.02*s)*(...)"
            )
        if self.den.size == other.den.size and np.allclose(self.den, other.den, rtol=1e-12, atol=0):
            return _Term(np.polyadd(self.num, other.num), self.den, self.delay)
        num = np.polyadd(np.polymul(self.num, other.den), np.polymul(other.num, self.den))
        den = np.polymul(self.den, other.den)
        num, den = _cancel_shared(num, den, self.den, other.den)
        return _Term(num, den, self.delay)

    def __neg__(self) -> _Term:
        return _Term(-self.num, self.den, self.delay)

    def __sub__(self, other: _Term) -> _Term:
        return self + (-other)

    def __mul__(self, other: _Term) -> _Term:
        return _Term(
            np.polymul(self.num, other.num),
            np.polymul(self.den, other.den),
            self.delay + other.delay,
        )

    def __truediv__(self, other: _Term) -> _Term:
        if _is_zero(other.num):
            raise ModelError("division by zero")
        return _Term(
            np.polymul(self.num, other.den),
            np.polymul(self.den, other.num),
            self.delay - other.delay,
        )

    def __pow__(self, exponent: int) -> _Term:
        if exponent >= 0:
            num, den = np.array([1.0]), np.array([1.0])
            for _ in range(exponent):
                num, den = np.polymul(num, self.num), np.polymul(den, self.den)
            return _Term(num, den, self.delay * exponent)
        return _Term.constant(1.0) / (self ** (-exponent))


def _trim(p: np.ndarray) -> np.ndarray:
    p = np.atleast_1d(p)
    nonzero = np.flatnonzero(p != 0.0)
    return p[nonzero[0]:] if nonzero.size else np.array([0.0])


def _is_zero(p: np.ndarray) -> bool:
    return bool(np.all(p == 0.0))


def _cancel_shared(num: np.ndarray, den: np.ndarray, den_a: np.ndarray, den_b: np.ndarray):
    """Remove factors that both input denominators shared (added by cross-multiplying)."""
    if den_a.size < 2 or den_b.size < 2:
        return num, den
    roots_a = list(np.roots(den_a))
    shared = []
    for r in np.roots(den_b):
        for i, ra in enumerate(roots_a):
            if abs(r - ra) <= 1e-9 * (1.0 + abs(r)):
                shared.append(ra)
                roots_a.pop(i)
                break
    for r in shared:
        factor = np.poly([r]).real if abs(np.imag(r)) < 1e-12 else None
        if factor is None:
            continue  # complex shared roots are left alone; harmless for evaluation
        qn, rn = np.polydiv(num, factor)
        qd, rd = np.polydiv(den, factor)
        scale_n = max(1.0, float(np.max(np.abs(num))))
        scale_d = max(1.0, float(np.max(np.abs(den))))
        if np.max(np.abs(rn)) <= 1e-9 * scale_n and np.max(np.abs(rd)) <= 1e-9 * scale_d:
            num, den = qn, qd
    return num, den


_IMPLICIT_RULES = [
    (re.compile(r"(?<=[0-9.)])\s*(?=\()"), "*"),  # 2(  )(
    (re.compile(r"(?<=[0-9.)])\s*(?=s\b)"), "*"),  # 2s  )s
    (re.compile(r"(?<=[0-9.)])\s*(?=exp\b)"), "*"),  # 2exp  )exp
    (re.compile(r"\bs\s*(?=[(0-9])"), "s*"),  # s(  s2 (rare)
]


def _normalize(text: str) -> str:
    expr = text.replace("^", "**").strip()
    # protect scientific notation (1e-3) from the implicit-multiplication rules
    expr = re.sub(r"(\d)[eE]([+-]?\d)", r"\1E\2", expr)
    for pattern, repl in _IMPLICIT_RULES:
        expr = pattern.sub(repl, expr)
    return expr


def parse_tf(text: str) -> ParsedTF:
    """Parse a transfer-function string.

    Parameters
    ----------
    text : str
        An expression in ``s`` such as ``"23*(s+0.43)/((s+9.6)*(s+0.54))"``,
        ``"exp(-0.02*s)/(s+1)"`` or ``"1/(s^2+s+1)"``.

    Returns
    -------
    ParsedTF
        Numerator and monic denominator coefficients (descending powers) and
        the delay in seconds.

    Raises
    ------
    ModelError
        If the text cannot be parsed, uses names other than ``s`` and
        ``exp``, has a non-integer power of ``s``, a negative delay
        (a predictor), or is improper (numerator degree above the
        denominator's).

    Examples
    --------
    >>> tf = parse_tf("23*(s+0.43)/((s+9.6)*(s+0.54))")
    >>> [round(c, 3) for c in tf.num], [round(c, 3) for c in tf.den], tf.delay
    ([23.0, 9.89], [1.0, 10.14, 5.184], 0.0)
    >>> parse_tf("exp(-0.02*s)*2/(s+1)").delay
    0.02
    """
    if not isinstance(text, str) or not text.strip():
        raise ModelError("empty transfer function; write it in s, e.g. '1/(s+1)'")
    return _parsed(text)


@lru_cache(maxsize=256)
def _parsed(text: str) -> ParsedTF:
    """:func:`parse_tf` of a non-empty string, kept: a spec's plants are built from their text at every check
    of a search (1 ms each); the result is frozen, and errors are raised again (not kept)."""
    source = _normalize(text)
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        raise ModelError(f"cannot parse transfer function {text!r}: {exc.msg}") from None
    try:
        term = _eval(tree.body)
    except ModelError as exc:
        raise ModelError(f"transfer function {text!r}: {exc.message}") from None
    num, den, delay = term.num, term.den, term.delay
    if _is_zero(den):
        raise ModelError(f"transfer function {text!r} has a zero denominator")
    if delay < -1e-15:
        raise ModelError(
            f"transfer function {text!r} has exp(+{-delay:g}*s), a predictor; "
            "only delays exp(-tau*s) with tau >= 0 are physical"
        )
    if num.size > den.size and not _is_zero(num):
        raise ModelError(
            f"transfer function {text!r} is improper (numerator degree {num.size - 1} > "
            f"denominator degree {den.size - 1}); a physical plant or controller needs "
            "at least as many poles as zeros"
        )
    lead = den[0]
    num, den = num / lead, den / lead
    if not (np.all(np.isfinite(num)) and np.all(np.isfinite(den))):
        raise ModelError(f"transfer function {text!r} has non-finite coefficients")
    return ParsedTF(tuple(float(c) for c in num), tuple(float(c) for c in den), max(delay, 0.0))


def _eval(node: ast.AST) -> _Term:
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ModelError(f"unexpected constant {node.value!r}")
        return _Term.constant(float(node.value))
    if isinstance(node, ast.Name):
        if node.id == "s":
            return _Term(np.array([1.0, 0.0]), np.array([1.0]))
        raise ModelError(f"unknown name {node.id!r}; use 's' as the Laplace variable")
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = _eval(node.operand)
        return -inner if isinstance(node.op, ast.USub) else inner
    if isinstance(node, ast.BinOp):
        if isinstance(node.op, ast.Pow):
            base = _eval(node.left)
            exponent = _eval(node.right)
            if not exponent.is_constant():
                raise ModelError("exponents must be numbers")
            value = exponent.value()
            if base.is_constant():
                return _Term.constant(base.value() ** value)
            if value != int(value):
                raise ModelError(f"non-integer power {value:g} of an expression in s")
            return base ** int(value)
        left, right = _eval(node.left), _eval(node.right)
        if isinstance(node.op, ast.Add):
            return left + right
        if isinstance(node.op, ast.Sub):
            return left - right
        if isinstance(node.op, ast.Mult):
            return left * right
        if isinstance(node.op, ast.Div):
            return left / right
        raise ModelError(f"operator {type(node.op).__name__} is not allowed")
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or node.func.id not in _ALLOWED_FUNCS:
            name = getattr(node.func, "id", "?")
            raise ModelError(f"unknown function {name!r}; only exp(-tau*s) is allowed")
        if len(node.args) != 1 or node.keywords:
            raise ModelError("exp takes exactly one argument, e.g. exp(-0.02*s)")
        arg = _eval(node.args[0])
        if arg.delay != 0.0 or arg.den.size != 1 or arg.num.size != 2 or arg.num[1] != 0.0:
            raise ModelError("exp(...) must be a delay exp(-tau*s) with a number tau")
        slope = arg.num[0] / arg.den[0]
        return _Term(np.array([1.0]), np.array([1.0]), -slope)
    raise ModelError(f"unexpected syntax {ast.unparse(node)!r}")
