"""Small polynomial helpers (descending-power coefficient arrays, as numpy.polyval uses)."""

from __future__ import annotations

from typing import Any

import numpy as np

from synth.errors import ModelError

__all__ = ["dc_value", "format_factored", "horner", "largest_crossing", "magnitude_squared_in_w2", "mirror", "polymul",
           "shifted", "trim", "value_at_infinity"]


def trim(p: np.ndarray) -> np.ndarray:
    """Drop leading zero coefficients (keep ``[0.]`` for the zero polynomial).

    Examples
    --------
    >>> trim(np.array([0.0, 0.0, 1.0, 2.0]))
    array([1., 2.])
    """
    p = np.atleast_1d(np.asarray(p, dtype=float))
    if p.ndim == 1 and p.size and p[0] != 0.0:  # nothing to drop (most calls)
        return p
    nonzero = np.flatnonzero(p != 0.0)
    return p[nonzero[0]:] if nonzero.size else np.array([0.0])


def polymul(a: Any, b: Any) -> np.ndarray:
    """``np.polymul(a, b)`` of two coefficient arrays, bit for bit (leading zeros dropped, as its ``poly1d``
    drops them, then one convolution), without building ``poly1d`` objects (the design tests' 207,000 calls spent
    5.5 s of a 113 s profile in them).

    Examples
    --------
    >>> polymul(np.array([0.0, 1.0, 2.0]), [1.0, 3.0])
    array([1., 5., 6.])
    >>> polymul([0.0], [1.0, 2.0])
    array([0., 0.])
    """
    return np.convolve(_leading(np.atleast_1d(a)), _leading(np.atleast_1d(b)))


def _leading(p: np.ndarray) -> np.ndarray:
    if p.size and p[0] != 0:
        return p
    nonzero = np.flatnonzero(p)
    return p[nonzero[0]:] if nonzero.size else np.zeros(1, p.dtype)


def dc_value(num: np.ndarray, den: np.ndarray) -> Any:
    """``lim_{s -> 0} num(s)/den(s)``, exactly: common factors ``s`` cancel first, so a zero of one factor
    of a loop at the origin meets the pole of another (``0 * inf``) as a finite limit, never ``nan``.

    ``inf`` when the denominator keeps more factors ``s`` (a pole at the origin), 0 when the numerator
    does or is the zero polynomial. 2-D inputs are rows of polynomials (one limit per row).

    Examples
    --------
    >>> dc_value(np.polymul([2.0, 0.0], [1.0]), np.polymul([1.0, 0.0], [1.0, 4.0]))  # 2s / (s (s+4))
    0.5
    >>> dc_value(np.array([1.0]), np.array([1.0, 0.0])), dc_value(np.array([0.0]), np.array([1.0, 0.0]))
    (inf, 0.0)
    >>> dc_value(np.array([[0.0, 3.0], [1.0, 0.0]]), np.array([[1.0, 0.0], [2.0, 0.0]])).tolist()
    [inf, 0.5]
    """
    num, den = np.asarray(num, dtype=float), np.asarray(den, dtype=float)
    one = num.ndim == 1
    num, den = np.atleast_2d(num), np.atleast_2d(den)
    rows = np.arange(num.shape[0])
    zn = np.argmax(num[:, ::-1] != 0.0, axis=1)  # number of factors s (0 for the zero polynomial)
    zd = np.argmax(den[:, ::-1] != 0.0, axis=1)
    vn = num[rows, num.shape[1] - 1 - zn]
    vd = den[rows, den.shape[1] - 1 - zd]
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(zd > zn, np.inf, np.where(zn > zd, 0.0, vn / vd))
    out = np.where(np.any(num != 0.0, axis=1), out, 0.0)
    return float(out[0]) if one else out


def value_at_infinity(num: np.ndarray, den: np.ndarray) -> float:
    """``lim num(s)/den(s)`` for ``s -> inf``: the ratio of the leading coefficients of a biproper ratio, 0 for a
    strictly proper one (or a zero numerator), ``inf`` for an improper one.

    Examples
    --------
    >>> value_at_infinity(np.array([2.0, 4.0]), np.array([1.0, 1.0]))
    2.0
    >>> value_at_infinity(np.array([3.0]), np.array([1.0, 1.0]))
    0.0
    """
    num, den = trim(np.asarray(num, float)), trim(np.asarray(den, float))
    if not np.any(num):
        return 0.0
    if num.size > den.size:
        return float("inf")
    return float(num[0] / den[0]) if num.size == den.size else 0.0


def shifted(p: np.ndarray, f: float) -> np.ndarray:
    """Coefficients of ``p(s - f)`` (roots moved right by ``f``).

    Examples
    --------
    >>> shifted(np.array([1.0, 2.0]), 0.5)  # s + 2 -> s + 1.5
    array([1. , 1.5])
    """
    p = trim(p)
    step = np.array([1.0, -float(f)])
    out = p[:1]
    for c in p[1:]:  # Horner's scheme on polynomials: out * (s - f) + c
        out = np.convolve(out, step)
        out[-1] += c
    return out


def mirror(p: np.ndarray) -> np.ndarray:
    """Coefficients of ``p(-s)``.

    Examples
    --------
    >>> mirror(np.array([1.0, 2.0, 3.0]))
    array([ 1., -2.,  3.])
    """
    p = np.asarray(p, dtype=float)
    signs = (-1.0) ** np.arange(p.size - 1, -1, -1)
    return p * signs


def magnitude_squared_in_w2(p: np.ndarray) -> np.ndarray:
    """Polynomial ``m(x)`` with ``m(w**2) = |p(j w)|**2`` (coefficients in descending ``x``).

    Examples
    --------
    >>> m = magnitude_squared_in_w2(np.array([1.0, 1.0]))  # |jw + 1|^2 = w^2 + 1
    >>> m
    array([1., 1.])
    """
    q = polymul(np.asarray(p, float), mirror(p))  # even polynomial in s
    even = q[::-1][0::2]  # coefficients of s^0, s^2, s^4, ...
    signs = (-1.0) ** np.arange(even.size)  # (j w)^(2m) = (-1)^m w^(2m)
    return trim((even * signs)[::-1])


def largest_crossing(num: np.ndarray, den: np.ndarray, level: float) -> float:
    """Largest ``w >= 0`` with ``|num(jw)/den(jw)| == level`` (0 if there is none).

    Beyond the returned frequency the magnitude stays on one side of ``level``.
    Exact: it solves ``|num|^2 - level^2 |den|^2 = 0`` as a polynomial in ``w**2``.

    Examples
    --------
    >>> round(largest_crossing(np.array([10.0]), np.array([1.0, 1.0]), 1.0), 4)  # |10/(jw+1)| = 1
    9.9499
    """
    with np.errstate(over="ignore", invalid="ignore"):
        q = np.polysub(magnitude_squared_in_w2(num), level**2 * magnitude_squared_in_w2(den))
    if not np.all(np.isfinite(q)):
        largest = max(float(np.max(np.abs(num))), float(np.max(np.abs(den))))
        raise ModelError(f"a loop's magnitude overflows double precision (coefficients up to {largest:.3g}): "
                         "rescale the plant's or the controller's units")
    q = trim(q)
    if q.size < 2:
        return 0.0
    roots = np.roots(q)
    real = roots[(np.abs(roots.imag) <= 1e-9 * (1 + np.abs(roots.real))) & (roots.real > 0)].real
    return float(np.sqrt(real.max())) if real.size else 0.0


def _fmt(x: float, digits: int) -> str:
    text = f"{x:.{digits}g}"
    if "e" in text:
        mant, exp = text.split("e")
        text = f"{mant}e{int(exp)}"
    return text


def _factors(p: np.ndarray, digits: int) -> tuple[float, list[str]]:
    p = trim(p)
    gain = float(p[0])
    if p.size == 1:
        return gain, []
    roots = np.roots(p)
    scale = max(1.0, float(np.max(np.abs(roots))))
    n_zero = int(np.sum(np.abs(roots) <= 1e-12 * scale))
    rest = roots[np.abs(roots) > 1e-12 * scale]
    real = sorted(rest[np.abs(rest.imag) <= 1e-9 * np.abs(rest)].real, key=lambda r: -abs(r))
    cplx = rest[(np.abs(rest.imag) > 1e-9 * np.abs(rest)) & (rest.imag > 0)]
    cplx = sorted(cplx, key=lambda r: -abs(r))
    factors = []
    for r in real:
        a = -r
        factors.append(f"(s+{_fmt(a, digits)})" if a >= 0 else f"(s-{_fmt(-a, digits)})")
    for r in cplx:
        b, c = -2.0 * r.real, abs(r) ** 2
        sign = "+" if b >= 0 else "-"
        factors.append(f"(s^2{sign}{_fmt(abs(b), digits)}*s+{_fmt(c, digits)})")
    if n_zero:
        factors.append("s" if n_zero == 1 else f"s^{n_zero}")
    return gain, factors


def format_factored(num: np.ndarray, den: np.ndarray, digits: int = 4) -> str:
    """Factored text of ``num/den``, e.g. ``'23*(s+0.43)/((s+9.6)*(s+0.54))'``.

    Examples
    --------
    >>> format_factored(np.array([2.0]), np.array([1.0, 1.0, 0.0]))
    '2/((s+1)*s)'
    """
    gn, fn = _factors(num, digits)
    gd, fd = _factors(den, digits)
    gain = gn / gd
    if fn:
        if np.isclose(gain, 1.0):
            top = "*".join(fn)
        elif np.isclose(gain, -1.0):
            top = "-" + "*".join(fn)
        else:
            top = _fmt(gain, digits) + "*" + "*".join(fn)
    else:
        top = _fmt(gain, digits)
    if not fd:
        return top
    bottom = fd[0] if len(fd) == 1 and fd[0].startswith("(") else "(" + "*".join(fd) + ")"
    if len(fd) == 1 and not fd[0].startswith("("):
        bottom = fd[0]
    return f"{top}/{bottom}"


def horner(coeffs: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Evaluate one polynomial per row: ``coeffs`` is ``(n, k)`` (descending powers, zero-padded on the
    left), ``x`` is ``(n, m)`` or broadcastable to it; the same arithmetic as ``np.polyval`` row by row.

    Examples
    --------
    >>> horner(np.array([[1.0, 2.0], [0.0, 3.0]]), np.array([[1.0, 2.0], [1.0, 2.0]]))
    array([[3., 4.],
           [3., 3.]])
    """
    coeffs = np.asarray(coeffs)
    x = np.asarray(x)
    y = np.zeros(np.broadcast_shapes(x.shape, coeffs.shape[:1] + (1,) * (x.ndim - 1)), dtype=np.result_type(x, coeffs))
    column = (-1,) + (1,) * (x.ndim - 1)
    for j in range(coeffs.shape[1]):  # y = y * x + c, in place (the same operations, no temporaries)
        y *= x
        y += coeffs[:, j].reshape(column)
    return y
