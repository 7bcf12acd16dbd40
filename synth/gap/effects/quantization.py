"""Command quantization, and the dense joint search of its step and offset.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``quantization``       input     :class:`synth.sim.blocks.Quantizer` before ``G``             ``step, offset``
=====================  ========  ===========================================================  ==============

A quantizer is searched differently from the other effects (:func:`quantizer_grid`): for a fixed
denominator its training SSR depends on ``(step, offset)`` only through which lattice level each
command sample rounds to (the level values themselves are absorbed by the least-squares gain and
constant), so the cost is piecewise constant and a golden-section search is meaningless. Both
parameters are searched densely and jointly instead, every point by superposition of the unit
numerators' step responses (one FFT convolution per point, batched).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from functools import partial
from typing import ClassVar

import numpy as np
from scipy.fft import irfft, next_fast_len, rfft

from synth.errors import ModelError
from synth.forked import run_beside
from synth.gap.effects.base import Effect, Params, command_span, log_grid, unit_numerators
from synth.ident.simulate import simulate_plant
from synth.plant import Plant
from synth.sim.blocks import Quantizer

__all__ = ["QuantizationEffect", "batch_ssr", "batch_width", "quantizer_grid", "step_responses"]

_GRAM_VALUES = 600  # distinct command values up to which the dense search uses their Gram matrix
_GRAM_ENTRIES = 2.5e7  # ... and entries of the response table it is formed from (samples x columns)
_DENSE_SAMPLES = 20000  # a longer record that fits neither is searched on a prefix (see quantizer_grid)


@dataclass(frozen=True)
class QuantizationEffect(Effect):
    """Command resolution ``step`` with the lattice at ``offset + k step`` (:class:`synth.sim.blocks.Quantizer`).

    ``offset`` in ``[0, step)`` places the lattice relative to the signal (a converter's zero, a
    PWM's bias). For a fixed linear model the output depends on ``(step, offset)`` only through which
    level each sample rounds to, so the error is piecewise constant in both: they are searched densely
    and jointly on the record with the linear model's denominator fixed
    (:func:`quantizer_grid`, :meth:`data_grid`), never by a one-dimensional golden search.
    :meth:`grid` (no output data) is a coarse joint grid.

    Examples
    --------
    >>> import numpy as np
    >>> QuantizationEffect().input_map(np.array([0.4, 0.6, 1.7]), 1.0, {"step": 1.0}).tolist()
    [0.0, 1.0, 2.0]
    >>> QuantizationEffect().input_map(np.array([0.4, 0.6, 1.7]), 1.0, {"step": 1.0, "offset": 0.5}).tolist()
    [0.5, 0.5, 1.5]
    """

    name: ClassVar[str] = "quantization"
    parameter_names: ClassVar[tuple[str, ...]] = ("step", "offset")
    grid_names: ClassVar[tuple[str, ...]] = ("step", "offset")
    default_candidates: ClassVar[tuple[str, ...]] = ("quantization",)
    golden_search: ClassVar[bool] = False  # the cost is piecewise constant in step and offset

    def off(self) -> Params:
        return {"step": 0.0, "offset": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"step": (0.0, 0.5 * command_span(u)), "offset": (0.0, 0.5 * command_span(u))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        span = command_span(u)
        return [{**g, "offset": float(f * g["step"])} for g in log_grid(0.005 * span, 0.3 * span, 8, "step")
                for f in (0.0, 0.25, 0.5, 0.75)]

    def data_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant) -> list[Params]:
        """The best point of the dense joint search of :func:`quantizer_grid` on ``plant``.

        A subclass's own :meth:`grid` (a seeded search) wins.

        Examples
        --------
        >>> import numpy as np
        >>> t = np.arange(0, 8, 0.01); u = 1.0 + 0.8 * np.sin(2.3 * t) * np.sin(0.37 * t)
        >>> G = Plant.from_string("2/(0.2*s+1)")
        >>> y = QuantizationEffect().apply(G, t, u, {"step": 0.25, "offset": 0.07})
        >>> g = QuantizationEffect().data_grid(t, u, y, G)[0]
        >>> round(g["step"], 2), round(g["offset"], 2)
        (0.25, 0.07)
        """
        if type(self).grid is not QuantizationEffect.grid:
            return self.grid(t, u, plant)
        return quantizer_grid(plant, t, u, y, keep=1)

    def screen_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant,
                    mask: np.ndarray | None = None) -> list[Params]:
        """The best points of the dense joint search :func:`quantizer_grid` (no golden section: the cost is flat
        between the points where a sample changes level).

        Examples
        --------
        >>> t = np.arange(0, 8, 0.01); u = 1.0 + 0.8 * np.sin(2.3 * t) * np.sin(0.37 * t)
        >>> G = Plant.from_string("2/(0.2*s+1)")
        >>> y = QuantizationEffect().apply(G, t, u, {"step": 0.25, "offset": 0.07})
        >>> g = QuantizationEffect().screen_grid(t, u, y, G)
        >>> len(g), round(g[0]["step"], 2)
        (5, 0.25)
        """
        return quantizer_grid(plant, t, u, y, mask=mask)

    def seed_grid(self, point: Params, u_train: np.ndarray | None = None) -> list[Params]:
        """The screened point alone: the screen searched step and offset jointly and densely.

        Examples
        --------
        >>> QuantizationEffect().seed_grid({"step": 0.25, "offset": 0.07})
        [{'step': 0.25, 'offset': 0.07}]
        """
        return [dict(point)]

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        q = params.get("step", 0.0)
        return u if q <= 0 else Quantizer(q, float(params.get("offset", 0.0)) % q).apply(u, dt)


def step_responses(plant: Plant, t: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per unit numerator of ``plant``: the response to a unit step at ``t[0]`` from rest, and to a held 1 (steady).

    (The quantizer's dense search holds the denominator: a Gauss-Newton step in it would double the work of
    every one of its thousands of points; the best points are then screened like every other effect.)

    Examples
    --------
    >>> steps, consts = step_responses(Plant.from_string("2/(s+1)"), np.arange(0, 3, 1.0))
    >>> steps[0].round(3).tolist(), consts[0].round(3).tolist()
    ([0.0, 0.632, 0.865], [1.0, 1.0, 1.0])
    """
    units = unit_numerators(plant)
    ones = np.ones_like(t)
    return ([simulate_plant(g, t, ones, initial="zero") for g in units],
            [simulate_plant(g, t, ones) for g in units])


def batch_ssr(v: np.ndarray, y: np.ndarray, steps: list[np.ndarray], consts: list[np.ndarray],
              mask: np.ndarray | None = None) -> np.ndarray:
    """Least-squares SSR of ``y`` on the unit-numerator responses to each column of ``v`` plus a constant.

    ``v`` is ``(N, M)``: M candidate plant inputs. The response of a linear model started at the
    steady state of ``v[0]`` is ``v[0] c + sum_k (v[k] - v[k-1]) s[n - k]`` (``s`` the step response from
    rest, ``c`` the steady response to a held 1), so every column costs one FFT convolution per unit.

    Examples
    --------
    >>> t = np.arange(0, 5, 0.1); G = Plant.from_string("1/(s+1)")
    >>> steps, consts = step_responses(G, t)
    >>> v = np.column_stack([np.ones_like(t), np.where(t > 1, 1.0, 0.0)])
    >>> y = simulate_plant(G, t, v[:, 1], initial="zero")
    >>> batch_ssr(v, y, steps, consts).round(6).tolist()[1]
    0.0
    """
    n, m = v.shape
    dv = np.diff(v, axis=0)
    size = next_fast_len(2 * n - 1, real=True)  # a linear convolution of two n-sample signals, no wrap-around
    fdv = rfft(dv, size, axis=0)
    cols = []
    for s, c in zip(steps, consts):
        conv = irfft(fdv * rfft(s, size)[:, None], size, axis=0)[: n - 1]
        x = np.empty((n, m))
        x[0] = 0.0
        x[1:] = conv
        cols.append(x + v[0][None, :] * c[:, None])
    cols.append(np.ones((n, m)))
    X = np.stack(cols, axis=2)  # (N, M, k)
    if mask is not None:
        X, y = X[mask], y[mask]
    scale = np.maximum(np.sqrt(np.einsum("nmk,nmk->mk", X, X)), 1e-300)
    X = X / scale[None]
    gram = np.einsum("nmi,nmj->mij", X, X)
    xty = np.einsum("nmi,n->mi", X, y)
    coef = np.einsum("mij,mj->mi", np.linalg.pinv(gram, rcond=1e-10, hermitian=True), xty)
    return np.maximum(float(y @ y) - np.einsum("mi,mi->m", coef, xty), 0.0)


_BATCH_ENTRIES = 250_000
"""Samples times columns of one :func:`batch_ssr` call in the dense search (2 MB per array). Its FFT and
least-squares arrays are several times that; once they pass glibc's 32 MB ``mmap`` threshold every call maps fresh
pages that the kernel zeroes: 512 columns of a 20,000-sample record spent more time in the kernel than in numpy
(a 60,000-sample diagnosis: 16-20 s of system time, 48-55 s of wall time against 36 s with the threshold lifted).
Each column's arithmetic is the same whatever the batch, so the SSRs are the same bits. The passes over the search's
points keep their (values x points) rounding table within 2e6 entries for the same reason (it was 2e7: 160 MB per
temporary); a pass groups fewer points into distinct rounding patterns, and the search found the same points."""


_PASS_JOBS = 32
"""Jobs the dense search's passes are grouped in, taken in turn by this process and a forked child on the other core
(:func:`synth.forked.run_beside`; one process where forking is off). Each pass's costs are the same bits wherever it
runs."""


def batch_width(samples: int) -> int:
    """Columns per :func:`batch_ssr` call on a record of ``samples`` samples (16 to 512).

    Examples
    --------
    >>> batch_width(1000), batch_width(20000), batch_width(400000)
    (250, 16, 16)
    """
    return int(min(512, max(16, _BATCH_ENTRIES // max(samples, 1))))


class _LevelGram:
    """Least-squares SSR of ``y`` on the unit numerators' responses to ``v = L[u_index]`` plus a constant.

    The command takes few distinct values on a step train: the response to any ``v`` that maps each of
    them to a level is ``sum_j L_j r_j`` with ``r_j`` the response to the indicator of value ``j``. The Gram
    matrix of those responses (and the constant, and their products with ``y``) is formed once; every
    point then costs ``O(J^2)`` for ``J`` distinct values instead of an FFT convolution of the record
    (:func:`batch_ssr`, the same least squares).

    Examples
    --------
    >>> t = np.arange(0, 5, 0.1); G = Plant.from_string("1/(s+1)"); u = np.where(t > 1, 1.0, 0.0)
    >>> steps, consts = step_responses(G, t)
    >>> values, index = np.unique(u, return_inverse=True)
    >>> L = np.array([[0.0, 0.0], [1.0, 2.0]]); y = simulate_plant(G, t, 2.0 * u) + 0.3 * np.sin(t)
    >>> gram = _LevelGram(G, t, index, values.size, y)
    >>> np.allclose(gram.ssr(L), batch_ssr(L[index], y, steps, consts))
    True
    """

    def __init__(self, plant: Plant, t: np.ndarray, u_index: np.ndarray, n_values: int, y: np.ndarray,
                 mask: np.ndarray | None = None) -> None:
        units = unit_numerators(plant)
        cols = [simulate_plant(g, t, (u_index == j).astype(float)) for g in units for j in range(n_values)]
        R = np.column_stack([*cols, np.ones_like(t)])
        if mask is not None:
            R, y = R[mask], y[mask]
        self.k, self.n_values = len(units), n_values
        self.gram, self.xty, self.yy = R.T @ R, R.T @ y, float(y @ y)

    def ssr(self, levels: np.ndarray) -> np.ndarray:
        """SSR of every column of ``levels`` (``(J, M)``: each distinct value's level, per point)."""
        k, J, Q = self.k, self.n_values, self.gram
        m = levels.shape[1]
        q_l = [Q[:, i * J:(i + 1) * J] @ levels for i in range(k)] + [np.repeat(Q[:, -1:], m, axis=1)]
        gram = np.empty((m, k + 1, k + 1))
        xty = np.empty((m, k + 1))
        for a in range(k + 1):
            for c in range(k + 1):
                block = q_l[c]
                gram[:, a, c] = block[-1] if a == k else np.einsum("jm,jm->m", levels, block[a * J:(a + 1) * J])
            xty[:, a] = self.xty[-1] if a == k else self.xty[a * J:(a + 1) * J] @ levels
        scale = np.maximum(np.sqrt(np.maximum(np.einsum("mii->mi", gram), 0.0)), 1e-300)
        gram = gram / (scale[:, :, None] * scale[:, None, :])
        xty = xty / scale
        coef = np.einsum("mij,mj->mi", np.linalg.pinv(gram, rcond=1e-10, hermitian=True), xty)
        return np.maximum(self.yy - np.einsum("mi,mi->m", coef, xty), 0.0)


def quantizer_grid(plant: Plant, t: np.ndarray, u: np.ndarray, y: np.ndarray, keep: int = 5,
                   mask: np.ndarray | None = None) -> list[Params]:
    """Dense joint search of a command quantizer's ``step`` and ``offset`` with ``plant``'s denominator fixed.

    The lattice is written as ``c + (phase + k) step`` with ``c`` the command's mid-range, so changing the
    step at a fixed phase scales the lattice about the middle of the data instead of about zero. Steps run
    on a log grid from 0.005 to 0.5 of the command's span, spaced so that the lattice moves by at most an
    eighth of a step at the edges of the data between neighbours (relative spacing ``step / (4 span)``);
    phases on eight points in [0, 1). The best ``keep`` points are then searched again on a grid four times
    finer in both directions around each. Every point's SSR is the least-squares fit of the unit numerators
    and a constant (:func:`batch_ssr`).

    Parameters
    ----------
    plant : Plant
        Linear model whose denominator and delay are held fixed.
    t, u, y : numpy.ndarray
        Training record.
    keep : int
        Points refined, and returned, best first.
    mask : numpy.ndarray of bool, optional
        Samples that count in the SSR (default all).

    Returns
    -------
    list of dict
        ``{"step", "offset"}`` with ``offset`` in ``[0, step)`` (the :class:`synth.sim.blocks.Quantizer` offset).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 8, 0.01); u = 1.0 + 0.8 * np.sin(2.3 * t) * np.sin(0.37 * t)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> y = QuantizationEffect().apply(G, t, u, {"step": 0.25, "offset": 0.07})
    >>> g = quantizer_grid(G, t, u, y)[0]
    >>> abs(g["step"] / 0.25 - 1) < 0.01, abs(g["offset"] - 0.07) < 0.01
    (True, True)
    """
    t, u, y = (np.asarray(a, float) for a in (t, u, y))
    span = float(np.max(u) - np.min(u))
    if span <= 0:
        raise ModelError("the input is constant; no quantizer can be fitted", where="record.u")
    center = 0.5 * float(np.max(u) + np.min(u))
    levels_all = np.unique(u)
    n_use = _dense_samples(u, len(unit_numerators(plant)))
    if n_use < t.size:  # a long record: the search on its start (from rest, as the whole); points kept per the whole
        t, u, y, mask = t[:n_use], u[:n_use], y[:n_use], None if mask is None else np.asarray(mask)[:n_use]
    steps_r, consts = step_responses(plant, t)
    q_lo, q_hi = 0.005 * span, 0.5 * span
    steps = [q_lo]
    while steps[-1] < q_hi:
        steps.append(steps[-1] * (1.0 + steps[-1] / (4.0 * span)))
    n_phase = 8

    # the quantized command depends only on the levels the command's distinct values round to: on a step
    # train (few distinct values) many (step, phase) points give the same input, whose SSR is computed once
    u_values, u_index = np.unique(u, return_inverse=True)
    # few distinct values (a step train): Gram matrices of the responses to each value's indicator, once
    gram = (_LevelGram(plant, t, u_index, u_values.size, y, mask)
            if u_values.size <= _GRAM_VALUES and t.size * (len(steps_r) * u_values.size + 1) <= _GRAM_ENTRIES
            else None)

    chunk = max(64, int(2e6 // u_values.size))  # points per pass: the (values x points) level table within 16 MB
    width = 512 if gram is not None else batch_width(t.size)  # candidate inputs per least-squares batch
    # the SSR is unchanged by v -> a v + b when the steady responses are constant (gain in the numerator fit, the
    # offset in the constant column): then only the integer rounding pattern, less its first entry, matters
    affine = all(np.ptp(c) <= 1e-9 * max(np.max(np.abs(c)), 1e-300) for c in consts)

    def passes(points: np.ndarray, starts: list[int]) -> np.ndarray:  # points (M, 2): step, phase
        out = []
        for start in starts:
            q, ph = points[start:start + chunk, 0], points[start:start + chunk, 1]
            lat = center + ph * q
            k = np.floor((u_values[:, None] - lat[None, :]) / q[None, :] + 0.5)  # as the block rounds, per value
            levels = k - k[:1] if affine else lat[None, :] + q[None, :] * k
            distinct, which = _distinct_columns(levels)
            cost = np.empty(distinct.shape[1])
            for i in range(0, distinct.shape[1], width):
                cost[i:i + width] = (gram.ssr(distinct[:, i:i + width]) if gram is not None else
                                     batch_ssr(distinct[:, i:i + width][u_index], y, steps_r, consts, mask))
            out.append(cost[np.ravel(which)])
        return np.concatenate(out)

    def ssr(points: np.ndarray) -> np.ndarray:  # the passes shared with a forked child where the other core is free
        starts = list(range(0, len(points), chunk))
        per_job = -(-len(starts) // _PASS_JOBS)
        jobs = [partial(passes, points, starts[i:i + per_job]) for i in range(0, len(starts), per_job)]
        return np.concatenate(run_beside(jobs, lambda: None)[0])

    coarse = np.array([(q, (j + 0.5) / n_phase) for q in steps for j in range(n_phase)])
    cost = ssr(coarse)
    best = coarse[np.argsort(cost, kind="stable")[:keep]]
    fine = [coarse[np.argsort(cost, kind="stable")[:keep]]]
    for q, ph in best:
        dq = q / (4.0 * span)  # the coarse relative spacing
        fq = q * np.exp(np.linspace(-dq, dq, 9))
        fp = ph + np.linspace(-0.5, 0.5, 9) / n_phase
        fine.append(np.array([(a, b) for a in fq for b in fp]))
    pts = np.vstack(fine)
    cost = ssr(pts)
    order = np.argsort(cost, kind="stable")
    levels = levels_all
    digest = hashlib.blake2b(np.asarray(levels, float).tobytes(), digest_size=16).digest()
    out: list[Params] = []
    for i in order:
        q, ph = pts[i]
        g = _max_margin(levels, digest, float(q), float(center + ph * q))
        if g not in out:
            out.append(g)
        if len(out) == keep:
            break
    return out


def _distinct_columns(table: np.ndarray, key: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The distinct columns of ``table``, and for each column the index of its own among them: what
    ``np.unique(table, axis=1, return_inverse=True)`` gives, in another order, without sorting whole columns
    (which took a third of the quantizer search on a command of thousands of distinct values).

    Columns are grouped by ``key`` (default: a fixed random projection of each column); a column grouped with
    another is compared with it entry by entry, and one that differs (a collision of the projection) becomes a
    distinct column of its own.

    Examples
    --------
    >>> table = np.array([[1.0, 2.0, 1.0, 0.0], [3.0, 4.0, 3.0, 0.0]])
    >>> distinct, which = _distinct_columns(table)
    >>> distinct.shape[1], bool(np.array_equal(distinct[:, which], table))
    (3, True)
    >>> distinct, which = _distinct_columns(table, key=np.zeros(4))  # a projection that tells nothing apart
    >>> distinct.shape[1], which.tolist(), bool(np.array_equal(distinct[:, which], table))
    (3, [0, 1, 0, 2], True)
    """
    if key is None:
        key = np.random.default_rng(0).standard_normal(table.shape[0]) @ table
    _, first, which = np.unique(key, return_index=True, return_inverse=True)
    which = np.ravel(which)
    grouped = np.flatnonzero(first[which] != np.arange(table.shape[1]))
    differ = grouped[np.any(table[:, grouped] != table[:, first[which[grouped]]], axis=0)]
    if differ.size:  # colliding columns: each its own entry (identical ones among them are computed twice)
        which[differ] = first.size + np.arange(differ.size)
        first = np.concatenate([first, differ])
    return table[:, first], which


def _dense_samples(u: np.ndarray, units: int) -> int:
    """How many samples from the start the dense quantizer search uses: all of them, unless that is too much work.

    The whole record when its distinct values fit the Gram search (:class:`_LevelGram`: at most
    ``_GRAM_VALUES`` values and ``_GRAM_ENTRIES`` table entries) or it has at most ``_DENSE_SAMPLES``
    samples (an FFT per point, as always). A longer record: the longest prefix that fits the Gram search,
    or else the first ``_DENSE_SAMPLES``: the search's cost is then bounded whatever the length (the
    points it returns are screened on the whole record).

    Examples
    --------
    >>> steps = np.repeat(np.arange(1000.0), 100)  # 100,000 samples of 1,000 levels
    >>> _dense_samples(steps[:5000], 1), _dense_samples(steps, 1), _dense_samples(np.arange(30000.0), 1)
    (5000, 49900, 20000)
    """
    n = u.size
    first = np.sort(np.unique(u, return_index=True)[1])  # where each distinct value first appears
    counts = np.arange(1, first.size + 1)  # distinct values in the prefixes from each first appearance
    if (counts[-1] <= _GRAM_VALUES and n * (units * counts[-1] + 1.0) <= _GRAM_ENTRIES) or n <= _DENSE_SAMPLES:
        return n
    cap = np.minimum(np.r_[first[1:], n], _GRAM_ENTRIES // (units * counts + 1.0))  # longest prefix per count
    ok = (counts <= _GRAM_VALUES) & (cap > first)
    best = int(np.max(cap[ok])) if np.any(ok) else 0
    return best if best >= _DENSE_SAMPLES else _DENSE_SAMPLES


_CELLS: dict[tuple[bytes, bytes], tuple[float, float] | None] = {}
""":func:`_cell_centre`'s answers by (digest of the levels, of their lattice indices), all the program depends on:
the search asks for a few dozen cells from a thousand points (emptied past 4096 entries)."""


def _max_margin(levels: np.ndarray, digest: bytes, step: float, lattice: float) -> Params:
    """The point of the quantizer's cell farthest from rounding any of ``levels`` differently (``digest``: their
    hash, the cache's key with the rounding pattern).

    Every ``(step, offset)`` that rounds each level to the same lattice index ``n_i`` fits the
    training data equally well; the data do not tell them apart, and the one with the largest margin
    ``m`` (in steps) to the rounding boundaries is the least likely to round unseen levels wrongly. With
    ``a = 1/step``, ``b = offset/step`` the cell is ``n_i - 1/2 + m <= a u_i - b <= n_i + 1/2 - m``: a linear
    program in ``(a, b, m)``, solved once per rounding pattern. Returns the given point when the program fails.

    Examples
    --------
    >>> g = _max_margin(np.array([0.0, 1.0, 2.0]), b"example", 1.1, 0.3)  # rounds to 0, 1, 2: step 1, offset 0
    >>> round(g["step"], 6), round(g["offset"], 6) % 1.0
    (1.0, 0.0)
    """
    n = np.floor((levels - lattice) / step + 0.5)
    key = (digest, hashlib.blake2b((n - n[0]).tobytes(), digest_size=16).digest())
    if key not in _CELLS:
        if len(_CELLS) >= 4096:
            _CELLS.clear()
        _CELLS[key] = _cell_centre(levels, n - n[0])
    return _margin_params(_CELLS[key], step, lattice)


def _margin_params(centre: tuple[float, float] | None, step: float, lattice: float) -> Params:
    """The quantizer of the cell's centre ``(a, b)``, or the given point without one. The cell's indices count
    from the first level's: ``b`` differs from the lattice's by a whole number, which the offset ``(b step) mod
    step`` does not see; every point of a cell gives the same quantizer to the last bit."""
    if centre is None or centre[0] <= 0:
        return {"step": float(step), "offset": float(lattice % step)}
    q = 1.0 / centre[0]
    return {"step": q, "offset": float((centre[1] * q) % q)}


def _cell_centre(levels: np.ndarray, n: np.ndarray) -> tuple[float, float] | None:
    """``(a, b)`` of the largest-margin point of the cell where ``levels`` round to indices ``n`` (see
    :func:`_max_margin`); None when the program fails."""
    from scipy.optimize import linprog

    ones = np.ones_like(levels)
    # a u - b - m >= n - 1/2  ->  -a u + b + m <= 1/2 - n ;  a u - b + m <= n + 1/2
    a_ub = np.vstack([np.column_stack([-levels, ones, ones]), np.column_stack([levels, -ones, ones])])
    b_ub = np.concatenate([0.5 - n, n + 0.5])
    bounds = [(1e-12 / (float(np.ptp(levels)) or 1.0), None), (None, None), (0.0, 0.5)]
    try:
        res = linprog([0.0, 0.0, -1.0], A_ub=a_ub, b_ub=b_ub, bounds=bounds, method="highs")
        if not res.success:
            return None
        # the largest margin may be reached on a segment: take the middle of its ends in 1/step
        m = float(res.x[2]) * (1.0 - 1e-9)
        ends = [linprog([c, 0.0, 0.0], A_ub=a_ub, b_ub=b_ub, bounds=[*bounds[:2], (m, 0.5)], method="highs")
                for c in (1.0, -1.0)]
    except ValueError:
        return None
    x = 0.5 * (ends[0].x + ends[1].x) if all(e.success for e in ends) else res.x
    return float(x[0]), float(x[1])
