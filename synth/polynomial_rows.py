"""Polynomials as the rows of one array (highest power first, zero-padded on the left): products, roots and
magnitudes of many polynomials at once (:class:`synth.loop_batch.LoopBatch`)."""

from __future__ import annotations

import numpy as np

__all__ = ["pad_sub", "ragged_rows", "row_axis_parts", "row_corners", "row_magnitude_squared", "row_poly_product",
           "row_product", "row_rhp_counts", "row_roots", "row_unit_crossings"]


def row_magnitude_squared(rows: np.ndarray) -> np.ndarray:
    """Row-wise :func:`synth.polynomials.magnitude_squared_in_w2`: ``|p(jw)|^2`` as a polynomial in ``w^2``.

    Examples
    --------
    >>> row_magnitude_squared(np.array([[1.0, 2.0]])).tolist()  # |jw + 2|^2 = w^2 + 4
    [[1.0, 4.0]]
    """
    k = rows.shape[1]
    mirrored = rows * (-1.0) ** np.arange(k - 1, -1, -1)
    q = np.zeros((rows.shape[0], 2 * k - 1))
    for j in range(k):
        q[:, j:j + k] += rows * mirrored[:, j:j + 1]
    even = q[:, ::-1][:, 0::2] * (-1.0) ** np.arange((2 * k) // 2)
    return even[:, ::-1]


def row_axis_parts(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real and imaginary parts of ``p(jw)`` as real polynomials in ``w`` (row-wise).

    Examples
    --------
    >>> [a.tolist() for a in row_axis_parts(np.array([[1.0, 2.0]]))]  # jw + 2: real 2, imaginary w
    [[[0.0, 2.0]], [[1.0, 0.0]]]
    """
    k = rows.shape[1]
    power = np.arange(k - 1, -1, -1)
    unit = 1j ** power
    return rows * np.round(unit.real), rows * np.round(unit.imag)


def row_poly_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row ``i`` of ``a`` times row ``i`` of ``b``.

    Examples
    --------
    >>> row_poly_product(np.array([[1.0, 1.0]]), np.array([[1.0, 2.0]])).tolist()  # (s + 1)(s + 2)
    [[1.0, 3.0, 2.0]]
    """
    out = np.zeros((a.shape[0], a.shape[1] + b.shape[1] - 1))
    for j in range(b.shape[1]):
        out[:, j:j + a.shape[1]] += a * b[:, j:j + 1]
    return out


def pad_sub(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a - b`` row by row, the narrower one zero-padded on the left.

    Examples
    --------
    >>> pad_sub(np.array([[1.0, 0.0, 1.0]]), np.array([[2.0, 3.0]])).tolist()
    [[1.0, -2.0, -2.0]]
    """
    width = max(a.shape[1], b.shape[1])
    return np.pad(a, ((0, 0), (width - a.shape[1], 0))) - np.pad(b, ((0, 0), (width - b.shape[1], 0)))


def row_roots(rows: np.ndarray) -> list[np.ndarray]:
    """Roots of each row's polynomial (leading zeros dropped), one batched eigenvalue problem per degree.

    Examples
    --------
    >>> [np.sort(r.real).round(6).tolist() for r in row_roots(np.array([[0.0, 1.0, 1.0], [1.0, 3.0, 2.0]]))]
    [[-1.0], [-2.0, -1.0]]
    """
    lead = np.argmax(rows != 0, axis=1)
    zero = ~np.any(rows != 0, axis=1)
    degree = np.where(zero, 0, rows.shape[1] - 1 - lead)
    out: list[np.ndarray] = [np.zeros(0, complex)] * rows.shape[0]
    for d in np.unique(degree):
        sel = np.flatnonzero(degree == d)
        if d < 1:
            continue
        coeffs = np.array([rows[i, lead[i]:] for i in sel])
        comp = np.zeros((len(sel), d, d))
        comp[:, 0, :] = -coeffs[:, 1:] / coeffs[:, :1]
        comp[:, np.arange(1, d), np.arange(d - 1)] = 1.0
        roots = np.linalg.eigvals(comp)
        for j, i in enumerate(sel):
            out[i] = roots[j]
    return out


def row_unit_crossings(q: np.ndarray) -> list[np.ndarray]:
    """The positive real ``w`` (sorted) where each row's ``|N|^2 - |D|^2``, a polynomial in ``w^2``, is zero: the
    gain crossovers of ``N/D``.

    Examples
    --------
    >>> [w.round(4).tolist() for w in row_unit_crossings(np.array([[-1.0, 99.0], [-1.0, -1.0]]))]  # 10/(s+1); none
    [[9.9499], []]
    """
    out = []
    for r in row_roots(q):
        keep = (np.abs(r.imag) <= 1e-9 * (1 + np.abs(r.real))) & (r.real > 0)
        out.append(np.sort(np.sqrt(r[keep].real)))
    return out


def row_product(rows: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Each row's polynomial times ``poly`` (rows zero-padded on the left).

    Examples
    --------
    >>> row_product(np.array([[1.0, 1.0]]), np.array([2.0, 0.0])).tolist()  # (s + 1) 2s
    [[2.0, 2.0, 0.0]]
    """
    poly = np.asarray(poly, dtype=float)
    out = np.zeros((rows.shape[0], rows.shape[1] + poly.size - 1))
    for j, c in enumerate(poly):
        out[:, j:j + rows.shape[1]] += rows * c
    return out


def row_rhp_counts(num: np.ndarray, den: np.ndarray, floor: float) -> np.ndarray:
    """Right-half-plane roots of ``den + num`` for each pair of rows (the closed loop of ``num/den`` without a
    delay), counted as :func:`synth.stability.closed_loop_stability` counts them with the stability ``floor``,
    from the roots of all rows in batched eigenvalue problems: where every root is clear of the band from
    ``-2 floor`` to the axis by ``1e-6`` of its magnitude. ``-1`` (to be counted one by one) for a row with a
    root in that band, an improper ``num/den``, or a ``den + num`` that loses the leading power of ``den``.

    Examples
    --------
    ``1/(s - 1)`` with gains 0.5, 2 and 1 (a root at 0: counted one by one):

    >>> row_rhp_counts(np.array([[0.5], [2.0], [1.0]]), np.array([[1.0, -1.0]] * 3), 1e-6).tolist()
    [1, 0, -1]
    """
    width = max(num.shape[1], den.shape[1])
    num = np.pad(num, ((0, 0), (width - num.shape[1], 0)))
    den = np.pad(den, ((0, 0), (width - den.shape[1], 0)))
    counts = np.full(num.shape[0], -1)
    lead_num, lead_den = np.argmax(num != 0, axis=1), np.argmax(den != 0, axis=1)
    char = den + num
    proper = np.any(den != 0, axis=1) & (~np.any(num != 0, axis=1) | (lead_num >= lead_den))
    keeps = proper & (char[np.arange(num.shape[0]), lead_den] != 0.0)
    for i, r in zip(np.flatnonzero(keeps), row_roots(char[keeps])):
        scale = 1e-6 * np.maximum(1.0, np.abs(r))
        if not np.any((r.real >= -2.0 * floor - scale) & (r.real <= scale)):
            counts[i] = int(np.sum(r.real > 0.0))
    return counts


def row_corners(*rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The smallest and largest root magnitude (above 1e-12) over the same row of every array (each row one
    polynomial): :func:`synth.freqgrid.corner_frequencies` of every row at once; NaN where a row has none.

    Examples
    --------
    >>> lo, hi = row_corners(np.array([[1.0, 2.0], [0.0, 1.0]]), np.array([[1.0, 10.0], [1.0, 0.0]]))
    >>> lo.tolist(), hi.tolist()
    ([2.0, nan], [10.0, nan])
    """
    n = rows[0].shape[0]
    lo, hi = np.full(n, np.inf), np.full(n, -np.inf)
    for r in rows:
        for i, roots in enumerate(row_roots(r)):
            mags = np.abs(roots)
            mags = mags[mags > 1e-12]
            if mags.size:
                lo[i], hi[i] = min(lo[i], mags.min()), max(hi[i], mags.max())
    none = ~np.isfinite(lo)
    return np.where(none, np.nan, lo), np.where(none, np.nan, hi)


def ragged_rows(rows: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """``values`` grouped by their row (``rows`` sorted or not) into an ``(n, k)`` array padded with NaN.

    Examples
    --------
    >>> ragged_rows(np.array([1, 0, 1]), np.array([5.0, 6.0, 7.0]), 3).tolist()
    [[6.0, nan], [5.0, 7.0], [nan, nan]]
    """
    out = np.full((n, max(1, int(np.bincount(rows, minlength=n).max()) if rows.size else 1)), np.nan)
    order = np.argsort(rows, kind="stable")
    rows, values = rows[order], values[order]
    start = np.searchsorted(rows, np.arange(n))
    out[rows, np.arange(rows.size) - start[rows]] = values
    return out
