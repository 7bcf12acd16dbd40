"""Many loops of one plant at once: the responses of ``Loop(plant, c)`` for a list of controllers,
evaluated vectorized (all loops and frequencies in one array), for the one-parameter feasible set,
the report's slack curves and feasibility maps (see :meth:`synth.requirements.base.Requirement.batch_slack`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from synth.controllers import Controller, as_controller
from synth.freqgrid import corner_frequencies, log_grids
from synth.plant import Plant, as_plant
from synth.polynomial_rows import (
    pad_sub,
    ragged_rows,
    row_axis_parts,
    row_corners,
    row_magnitude_squared,
    row_poly_product,
    row_product,
    row_rhp_counts,
    row_roots,
    row_unit_crossings,
)
from synth.polynomials import dc_value, horner
from synth.rootfind import bisect_roots

__all__ = ["LoopBatch"]


def _rows(polys: list[np.ndarray]) -> np.ndarray:
    width = max(p.size for p in polys)
    out = np.zeros((len(polys), width))
    for i, p in enumerate(polys):
        out[i, width - p.size:] = p
    return out


class LoopBatch:
    """One plant with many controllers: the loops' responses evaluated all at once (vectorized).

    Row ``i`` is ``Loop(plant, controllers[i])``; every response takes frequencies of shape ``(m,)``
    (the same for every row) or ``(n, m)`` (one row of frequencies per loop) and returns ``(n, m)``,
    with the same arithmetic and the same conventions as :class:`Loop` (``L = inf`` at a loop pole on
    the axis, ``S = 0`` and ``T = 1`` there).

    Parameters
    ----------
    plant : Plant
    controllers : list of Controller

    Examples
    --------
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
    >>> batch = LoopBatch(G, [Controller("P", {"kp": k}) for k in (1.0, 3.0)])
    >>> w = np.array([1.0, 100.0])
    >>> from synth.loop import Loop
    >>> bool(np.allclose(batch.T(w)[1], Loop(G, Controller("P", {"kp": 3.0})).T(w)))
    True
    >>> batch.T0().round(4)
    array([0.6561, 0.8513])
    """

    def __init__(self, plant: Plant, controllers: list[Controller]) -> None:
        self.controllers = [as_controller(c) for c in controllers]
        tfs = [c.tf() for c in self.controllers]
        self.cnum = _rows([n for n, _ in tfs])
        self.cden = _rows([d for _, d in tfs])
        self._corner_lo, self._corner_hi = row_corners(self.cnum, self.cden)
        self._dc = np.array([c.dc_gain() for c in self.controllers])
        self._set_plant(as_plant(plant))

    def with_plant(self, plant: Plant) -> LoopBatch:
        """The same controllers around another plant (the controllers' polynomials are reused).

        Examples
        --------
        >>> b = LoopBatch(Plant.from_string("1/(s+1)"), [Controller("P", {"kp": 1.0})])
        >>> b.with_plant(Plant.from_string("2/(s+1)")).T0().round(4)
        array([0.6667])
        """
        new = object.__new__(LoopBatch)
        new.__dict__.update({k: v for k, v in self.__dict__.items()
                             if k in ("controllers", "cnum", "cden", "_corner_lo", "_corner_hi", "_dc")})
        new._set_plant(as_plant(plant))
        return new

    def _set_plant(self, plant: Plant) -> None:
        self.plant = plant
        self.num = row_product(self.cnum, plant.num)
        self.den = row_product(self.cden, plant.den)
        self._l0 = dc_value(self.num, self.den)  # L(0), the exact limit (s cancels first)
        p_lo, p_hi = corner_frequencies(plant.num, plant.den)
        if plant.delay > 0:
            p_lo, p_hi = min(p_lo, 1.0 / plant.delay), max(p_hi, 1.0 / plant.delay)
        lo, hi = np.fmin(self._corner_lo, p_lo), np.fmax(self._corner_hi, p_hi)
        none = np.isnan(lo)
        lo, hi = np.where(none, 1e-2, lo / 100.0), np.where(none, 1e2, hi * 100.0)
        with np.errstate(over="ignore", invalid="ignore"):
            q = pad_sub(row_magnitude_squared(self.num), row_magnitude_squared(self.den))
        finite = np.all(np.isfinite(q), axis=1)  # gains near 1e300 overflow |L|^2: their corners alone
        crossovers = row_unit_crossings(np.where(finite[:, None], q, 0.0))  # as Loop.frequency_range
        self._crossovers = crossovers if bool(np.all(finite)) else None  # gain_crossovers' answer, when exact
        lo = np.fmin(lo, np.array([w[0] / 100.0 if w.size else np.inf for w in crossovers]))
        hi = np.fmax(hi, np.array([w[-1] * 100.0 if w.size else 0.0 for w in crossovers]))
        self.frequency_ranges = np.column_stack([lo, hi])
        """Each loop's :attr:`Loop.frequency_range`, ``(n, 2)``."""

    def closed_loop_unstable(self) -> np.ndarray:
        """Per loop, whether a closed-loop root lies in the closed right half-plane (exact, by count:
        :meth:`unstable_root_counts`).

        Examples
        --------
        >>> G = Plant.from_string("10/((s-1)*(s+5))")
        >>> LoopBatch(G, [Controller("P", {"kp": k}) for k in (0.4, 2.0)]).closed_loop_unstable().tolist()
        [True, False]
        """
        return self.unstable_root_counts() > 0

    def unstable_root_counts(self) -> np.ndarray:
        """Per loop, the closed-loop roots in the closed right half-plane as :meth:`synth.loop.Loop.stability`
        counts them (delay and stability floor included; cached per plant). Loops that differ by a gain only
        (:meth:`gain_multiples`, at least 8 of them) are counted by D-decomposition in that gain
        (:func:`synth.stability_sets.affine_root_counts`), others one by one, unless the counts were
        given (:meth:`with_root_counts`).

        Examples
        --------
        >>> G = Plant.from_string("1/(s+1)^3")
        >>> LoopBatch(G, [Controller("P", {"kp": k}) for k in (1.0, 9.0)]).unstable_root_counts().tolist()
        [0, 2]
        """
        if getattr(self, "_counts", None) is None or self._counts_plant is not self.plant:
            counts = self._counts_by_gain()
            if counts is None:
                counts = self._counts_by_roots() if self.plant.delay == 0.0 else np.full(len(self), -1)
                loops = self.loops()
                for i in np.flatnonzero(counts < 0):  # a delay, or a root too near the line to judge in bulk
                    counts[i] = loops[i].stability().unstable_poles
            self._counts, self._counts_plant = counts, self.plant
        return self._counts

    def _counts_by_roots(self) -> np.ndarray:
        """Without a delay, the counts from the roots of ``den + num`` in bulk (:func:`row_rhp_counts`; -1 where a
        loop is to be counted one by one)."""
        from synth.stability import stability_floor

        p = self.plant
        return row_rhp_counts(self.num, self.den, stability_floor(p.num, p.den, p.delay))

    def loops(self) -> list[Any]:
        """``Loop(plant, c)`` for every controller, made once per plant: what they compute is kept (a count of
        :meth:`unstable_root_counts` made loop by loop is not made again by a requirement's scalar form).

        Examples
        --------
        >>> b = LoopBatch(Plant.from_string("1/(s+1)"), [Controller("P", {"kp": 1.0})])
        >>> b.loops()[0] is b.loops()[0], b.loops()[0].T0()
        (True, 0.5)
        """
        from synth.loop import Loop

        if getattr(self, "_loops_plant", None) is not self.plant:
            self._loops, self._loops_plant = [Loop(self.plant, c) for c in self.controllers], self.plant
        return self._loops

    def with_root_counts(self, counts: np.ndarray) -> LoopBatch:
        """The same loops with their :meth:`unstable_root_counts` given (e.g. read off a D-decomposition over
        a grid of one parameter, as the report's feasibility map does).

        Examples
        --------
        >>> b = LoopBatch(Plant.from_string("1/(s+1)"), [Controller("P", {"kp": 1.0})])
        >>> b.with_root_counts(np.array([0])).closed_loop_unstable().tolist()
        [False]
        """
        new = object.__new__(LoopBatch)
        new.__dict__.update(self.__dict__)
        new._counts, new._counts_plant = np.asarray(counts, int).copy(), self.plant
        return new

    def _counts_by_gain(self) -> np.ndarray | None:
        from synth.stability import stability_floor
        from synth.stability_sets import affine_root_counts

        multiples = self.gain_multiples() if len(self) >= 8 else None
        if multiples is None:
            return None
        r, c = multiples
        p = self.plant
        return affine_root_counts(None, (self.cnum[r], self.cden[r]), p.num, p.den, p.delay, c,
                                  stability_floor(p.num, p.den, p.delay))

    def __len__(self) -> int:
        return len(self.controllers)

    def _w(self, w: Any) -> np.ndarray:
        w = np.asarray(w, dtype=float)
        return np.broadcast_to(w, (len(self), w.shape[-1])) if w.ndim == 1 else w

    def L(self, w: Any) -> np.ndarray:
        """Loop responses ``C_i(jw) G(jw)``, ``(n, m)``."""
        s = 1j * self._w(w)
        d = horner(self.den, s)
        with np.errstate(divide="ignore", invalid="ignore"):
            L = horner(self.num, s) / d * np.exp(-s * self.plant.delay)
        return np.where(d == 0, complex(np.inf, 0.0), L)

    def C(self, w: Any) -> np.ndarray:
        """Controller responses ``C_i(jw)``, ``(n, m)``."""
        s = 1j * self._w(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            return horner(self.cnum, s) / horner(self.cden, s)

    def S(self, w: Any) -> np.ndarray:
        """Sensitivities ``1/(1 + L)``."""
        L = self.L(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(_infinite(L), 0j, 1.0 / (1.0 + L))

    def T(self, w: Any) -> np.ndarray:
        """Complementary sensitivities ``L/(1 + L)``."""
        L = self.L(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            T = L / (1.0 + L)
        return np.where(_infinite(L), 1.0 + 0j, T)

    def KS(self, w: Any) -> np.ndarray:
        """Control sensitivities ``C/(1 + C G)`` (``1/G`` where a controller has a pole on the axis)."""
        w = self._w(w)
        C = self.C(w)
        G = self.plant.freqresp(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            KS = C / (1.0 + C * G)
            return np.where(_infinite(C) | np.isnan(C), 1.0 / G, KS)

    def T0(self) -> np.ndarray:
        """``|T(0)|`` of every loop (1 with integral action)."""
        l0 = self._l0
        with np.errstate(divide="ignore", invalid="ignore"):
            t0 = np.abs(l0 / (1.0 + l0))
        return np.where(np.isinf(l0), 1.0, t0)

    def controller_dc_gains(self) -> np.ndarray:
        """``C_i(0)`` (``inf`` with integral action)."""
        return self._dc.copy()

    def gain_multiples(self) -> tuple[int, np.ndarray] | None:
        """``(r, c)`` when every controller is ``c[i] >= 0`` times controller ``r`` (a P gain swept, or a
        lead-lag's gain): the loops then differ by a gain only, ``L_i = c[i] L_r``, and a requirement
        whose measure scales with the loop gain needs one exact evaluation; ``None`` otherwise.

        Examples
        --------
        >>> G = Plant.from_string("1/(s+1)")
        >>> r, c = LoopBatch(G, [Controller("P", {"kp": k}) for k in (0.0, 2.0, 5.0)]).gain_multiples()
        >>> r, c.tolist()
        (1, [0.0, 1.0, 2.5])
        >>> LoopBatch(G, [Controller("PI", {"kp": 1.0, "ki": k}) for k in (1.0, 2.0)]).gain_multiples() is None
        True
        """
        lead = np.argmax(self.cden != 0, axis=1)
        scale = self.cden[np.arange(len(self)), lead]
        if np.any(scale == 0) or np.any(lead != lead[0]):
            return None
        den = self.cden / scale[:, None]
        num = self.cnum / scale[:, None]
        nonzero = np.flatnonzero(np.any(num != 0, axis=1))
        if nonzero.size == 0:
            return None
        r = int(nonzero[0])
        ref = num[r]
        c = num @ ref / (ref @ ref)
        tol = 1e-12 * np.max(np.abs(num), axis=1, initial=0.0)[:, None] + 1e-300
        same_num = np.all(np.abs(num - c[:, None] * ref) <= tol, axis=1)
        same_den = np.all(np.abs(den - den[r]) <= 1e-12 * np.max(np.abs(den[r])), axis=1)
        if not (np.all(same_num) and np.all(same_den) and np.all(c >= 0)):
            return None
        c[r] = 1.0
        return r, c

    def gain_crossovers(self) -> list[np.ndarray]:
        """Each loop's :meth:`Loop.gain_crossovers` (exact polynomial roots, one eigenvalue problem per
        degree for all loops of that degree).

        Examples
        --------
        >>> b = LoopBatch(Plant.from_string("10/(s+1)"), [Controller("P", {"kp": k}) for k in (1.0, 0.05)])
        >>> [w.round(4) for w in b.gain_crossovers()]
        [array([9.9499]), array([], dtype=float64)]
        """
        if self._crossovers is not None:  # found for the frequency ranges (every row finite)
            return list(self._crossovers)
        return row_unit_crossings(pad_sub(row_magnitude_squared(self.num), row_magnitude_squared(self.den)))

    def phase_and_delay_margins(self) -> tuple[np.ndarray, np.ndarray]:
        """Each loop's phase margin (deg) and delay margin (s) as :meth:`Loop.margins` gives them.

        Examples
        --------
        >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
        >>> pm, dm = LoopBatch(G, [Controller("P", {"kp": 3.0})]).phase_and_delay_margins()
        >>> round(float(pm[0]), 1)
        19.8
        """
        crossings = self.gain_crossovers()
        rows = np.concatenate([np.full(c.size, i) for i, c in enumerate(crossings)]).astype(int)
        wc = np.concatenate(crossings) if rows.size else np.zeros(0)
        pm, dm = np.full(len(self), np.inf), np.full(len(self), np.inf)
        if wc.size:
            s = 1j * wc
            with np.errstate(divide="ignore", invalid="ignore"):
                L = horner(self.num[rows], s[:, None])[:, 0] / horner(self.den[rows], s[:, None])[:, 0] \
                    * np.exp(-s * self.plant.delay)
            this = 180.0 - (-np.degrees(np.angle(L))) % 360.0  # wrapped to (-180, 180], as Loop.margins
            np.minimum.at(pm, rows, this)
            with np.errstate(divide="ignore", invalid="ignore"):
                # extra delay turns L(j wc) clockwise: the phase margin taken in (0, 360] deg, as Loop.margins
                turn = np.where(this > 0, this, this + 360.0)
                np.minimum.at(dm, rows, np.where(this != 0, np.radians(turn) / wc, 0.0))
        from synth.stability import neutral_with_any_delay

        neutral = np.array([neutral_with_any_delay(n, d) for n, d in zip(self.num, self.den)], dtype=bool)
        return pm, np.where(neutral, 0.0, dm)  # any added delay: neutral type (|L(j inf)| >= 1)

    def upper_gain_margins(self, limit: float = 1e4, per_decade: int = 100) -> np.ndarray:
        """Each loop's smallest gain factor above 1 that puts a closed-loop root on the imaginary axis
        (``inf`` if none up to ``limit``): the ``k_hi`` of :func:`synth.stability_sets.gain_margin_factors`
        (see :meth:`gain_margin_factors`).

        Examples
        --------
        >>> b = LoopBatch(Plant.from_string("1/(s+1)^3"), [Controller("P", {"kp": k}) for k in (1.0, 2.0)])
        >>> b.upper_gain_margins().round(6)
        array([8., 4.])
        """
        return self.gain_margin_factors(limit, per_decade)[1]

    def gain_margin_factors(self, limit: float = 1e4, per_decade: int = 100) -> tuple[np.ndarray, np.ndarray]:
        """Each loop's ``(k_lo, k_hi)`` of :func:`synth.stability_sets.gain_margin_factors`: the largest gain
        factor below 1 (above ``1/limit``, else 0) and the smallest above 1 (up to ``limit``, else ``inf``) that
        put a closed-loop root on the imaginary axis. Found for all loops at once from the real axis
        crossings of ``L(jw)`` (``w = 0`` included): exact polynomial roots without a delay; with one, the
        sign changes of ``Im L(jw)`` on a log grid four decades beyond :attr:`frequency_ranges` plus a few
        points per half turn of the delay's phase, refined by bisection.

        Examples
        --------
        An open-loop unstable plant needs ``k > 0.5`` (here ``kp = 2``: a factor 0.25 below):

        >>> b = LoopBatch(Plant.from_string("10/((s-1)*(s+5))"), [Controller("P", {"kp": 2.0})])
        >>> [x.round(6).tolist() for x in b.gain_margin_factors()]
        [[0.25], [inf]]
        """
        n = len(self)
        k_lo, k_hi = np.zeros(n), np.full(n, np.inf)
        todo = np.arange(n)
        for cap in (10.0, limit):  # as gain_margin_factors: most loops have a boundary below 10
            if todo.size == 0:
                break
            if self.plant.delay > 0:
                r = self._boundary_gains(todo, cap, per_decade)
            else:
                r = self._rational_boundary_gains()[todo]
            r = np.where(r <= cap, r, np.nan)
            above = np.where(r > 1.0 + 1e-12, r, np.inf)
            below = np.where((r < 1.0 - 1e-12) & (r > 1.0 / limit), r, 0.0)
            k_hi[todo] = np.nanmin(above, axis=1, initial=np.inf)
            k_lo[todo] = np.maximum(k_lo[todo], np.nanmax(below, axis=1, initial=0.0))
            todo = todo[~np.isfinite(k_hi[todo])]
        l0 = self._l0
        with np.errstate(divide="ignore", invalid="ignore"):
            r0 = np.where(np.isfinite(l0) & (l0 < 0), -1.0 / l0, np.nan)
        k_hi = np.minimum(k_hi, np.where((r0 > 1.0 + 1e-12) & (r0 <= limit), r0, np.inf))
        k_lo = np.maximum(k_lo, np.where((r0 < 1.0 - 1e-12) & (r0 > 1.0 / limit), r0, 0.0))
        return k_lo, k_hi

    def _rational_boundary_gains(self) -> np.ndarray:
        """Without a delay: ``-1/L(jw)`` at every exact phase crossover with ``Re L < 0`` (real roots of
        ``Im num(jw) conj(den(jw))``, batched polynomial roots), one row per loop, NaN-padded."""
        nr, ni = row_axis_parts(self.num)
        dr, di = row_axis_parts(self.den)
        h = pad_sub(row_poly_product(ni, dr), row_poly_product(nr, di))
        roots = row_roots(h)
        rows = np.concatenate([np.full(r.size, i) for i, r in enumerate(roots)] + [np.zeros(0)]).astype(int)
        wr = np.concatenate([*roots, np.zeros(0, complex)])
        keep = (np.abs(wr.imag) <= 1e-9 * (1 + np.abs(wr.real))) & (wr.real > 0)
        rows, w = rows[keep], wr.real[keep]
        Lc = self.rows_L(rows, w)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(Lc.real < 0, -1.0 / Lc.real, np.nan)
        far = self._at_infinity(np.arange(len(self)))  # a biproper loop's phase crossover at w -> inf
        ends = np.flatnonzero(far < 0)
        rows, r = np.concatenate([rows, ends]), np.concatenate([r, -1.0 / far[ends]])
        if rows.size == 0:
            return np.full((len(self), 1), np.nan)
        return ragged_rows(rows, r, len(self))

    def _boundary_gains(self, which: np.ndarray, cap: float, per_decade: int) -> np.ndarray:
        """``-1/L(jw)`` at the phase crossovers with ``Re L < 0`` of the loops ``which`` where
        ``|L| >= 0.5/cap`` (with a delay the grid resolves its phase up to there), one row per loop, NaN-padded.

        With a delay, each loop's grid gets a point every 0.3 rad of the delay's phase up to its own top frequency
        (at most 20,000): the loops are taken in groups whose tops need about as many points (powers of two),
        each group on its own even grid. One grid to the largest top for every loop cost 5.4 times the points on
        a screen of PI controllers behind 10 ms (259 loops; the highest gains' tops need 20,000 points, the
        median loop 414)."""
        ranges = self.frequency_ranges[which]
        grid = log_grids(ranges[:, 0] * 1e-2, ranges[:, 1] * 1e2, per_decade)
        far = np.abs(self._at_infinity(which))  # |L(j inf)|: a biproper loop's phase crossings never end
        if self.plant.delay == 0:
            local, r = self._crossing_gains(which, grid, far, None, cap)
        else:  # a few points per half turn of the delay's phase where |L| >= 0.5/cap
            big = np.abs(self.rows_L(np.repeat(which, grid.shape[1]), grid.ravel())).reshape(grid.shape) >= 0.5 / cap
            tops = 1.2 * np.max(np.where(big, grid, 0.0), axis=1)
            # beyond ten times the corners a biproper loop's crossings tend monotonically to the neutral factor
            # 1/|L(j inf)| (added below): two delay periods past there hold the first of them
            tops = np.where(far >= 0.5 / cap, np.minimum(tops, ranges[:, 1] / 10.0 + 4.0 * np.pi / self.plant.delay),
                            tops)
            groups = np.ceil(np.log2(_delay_points(tops, self.plant.delay))).astype(int)
            parts = []
            for g in np.unique(groups):
                members = np.flatnonzero(groups == g)
                w_top = float(np.max(tops[members]))
                extra = np.linspace(0.0, w_top, _delay_points(np.array([w_top]), self.plant.delay)[0])[1:]
                sub = np.sort(np.concatenate([grid[members], np.broadcast_to(extra, (members.size, extra.size))],
                                             axis=1), axis=1)
                local, r = self._crossing_gains(which[members], sub, far[members], tops[members], cap)
                parts.append((members[local], r))
            local = np.concatenate([m for m, _ in parts]).astype(int)
            r = np.concatenate([x for _, x in parts])
            neutral = np.flatnonzero(far > 0)  # the neutral factor: |k L(j inf)| = 1 (infinitely many roots come
            local = np.concatenate([local, neutral])  # to the axis)
            with np.errstate(divide="ignore"):
                r = np.concatenate([r, 1.0 / far[neutral]])
        if local.size == 0:
            return np.full((which.size, 1), np.nan)
        return ragged_rows(local, r, which.size)

    def _crossing_gains(self, which: np.ndarray, grid: np.ndarray, far: np.ndarray, tops: np.ndarray | None,
                        cap: float) -> tuple[np.ndarray, np.ndarray]:
        """For the loops ``which`` on their rows of ``grid``: the index (into ``which``) and ``-1/Re L`` of each real
        axis crossing (sign changes of ``Im L`` refined by bisection; NaN where ``Re L >= 0``). With a delay
        (``tops`` given) a biproper loop's crossings beyond its top are left out: there the log grid aliases the
        delay's phase, and the neutral factor holds them."""
        rows = np.repeat(which, grid.shape[1])
        L = self.rows_L(rows, grid.ravel()).reshape(grid.shape)
        im = np.where(_infinite(L), np.nan, L.imag)
        local, idx = np.nonzero(np.sign(im[:, :-1]) * np.sign(im[:, 1:]) < 0)
        if tops is not None and np.any(far >= 0.5 / cap):
            keep = (far[local] < 0.5 / cap) | (grid[local, idx + 1] <= tops[local])
            local, idx = local[keep], idx[keep]
        rows = which[local]
        wc = bisect_roots(lambda w, j: self.rows_L(rows[j], w).imag, grid[local, idx], grid[local, idx + 1],
                          indexed=True) if local.size else np.zeros(0)
        Lc = self.rows_L(rows, wc)
        with np.errstate(divide="ignore", invalid="ignore"):
            return local, np.where(Lc.real < 0, -1.0 / Lc.real, np.nan)

    def _at_infinity(self, which: np.ndarray) -> np.ndarray:
        """``L(j inf)`` without the delay's phase for the loops ``which``: the ratio of the leading coefficients of
        a biproper loop, 0 for a strictly proper one."""
        num, den = self.num[which], self.den[which]
        deg_n = num.shape[1] - 1 - np.argmax(num != 0, axis=1)
        deg_d = den.shape[1] - 1 - np.argmax(den != 0, axis=1)
        lead_n = num[np.arange(len(which)), np.argmax(num != 0, axis=1)]
        lead_d = den[np.arange(len(which)), np.argmax(den != 0, axis=1)]
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where((deg_n == deg_d) & np.any(num != 0, axis=1), lead_n / lead_d, 0.0)

    def rows_L(self, rows: np.ndarray, w: np.ndarray) -> np.ndarray:
        """``L`` of loop ``rows[j]`` at ``w[j]`` for every ``j`` (one frequency per entry), ``(len(w),)``.

        Examples
        --------
        >>> b = LoopBatch(Plant.from_string("1/(s+1)"), [Controller("P", {"kp": k}) for k in (1.0, 2.0)])
        >>> b.rows_L(np.array([1, 0]), np.array([0.0, 1.0])).round(3).tolist()
        [(2+0j), (0.5-0.5j)]
        """
        s = 1j * np.asarray(w, float)[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            return (horner(self.num[rows], s) / horner(self.den[rows], s))[:, 0] * np.exp(-s[:, 0] * self.plant.delay)


def _delay_points(tops: np.ndarray, delay: float) -> np.ndarray:
    """Points of an even grid from 0 to each top frequency with one every 0.3 rad of the delay's phase (2 more; at
    most 20,000)."""
    return np.minimum(np.ceil(np.asarray(tops, float) * delay / 0.3).astype(int) + 2, 20000)


def _infinite(x: np.ndarray) -> np.ndarray:
    return np.isinf(x.real) | np.isinf(x.imag)
