"""Which effect closes the gap, and how far: nested augmentations judged on held-out data.

Procedure (:func:`diagnose_effects`)
-----------------------------------
1. **Split.** With a validation record the fits use the whole record and the
   held-out data is the validation record. Without one, the first
   ``train_fraction`` of the record trains and the rest is held out (one
   contiguous block: the model is simulated over the whole record from rest,
   so the held-out part starts from the state the data put it in). The
   held-out samples are cut into ``blocks`` contiguous segments for the
   bootstrap.
2. **Fits.** The nominal model (only its output constant fitted on the
   training part), the re-fit of its coefficients alone
   (``parameter_mismatch``) and every candidate effect with the nominal
   coefficients re-fitted jointly (:func:`synth.gap.refit.fit_augmented`).
   With ``confirm=k`` every candidate is first *screened*
   (:mod:`synth.gap.screen`: the denominator held at the nominal's or the
   re-fit's, the rest by least squares, milliseconds per point) and only the
   ``k`` with the lowest screened training SSR are re-fitted jointly, started
   at the screened parameters; the others keep their screened fit (marked
   ``fit="screened"``), which can be significant and join a group but is never
   the verdict. ``confirm=None`` re-fits every candidate jointly.
3. **Held-out cost** ``J = mean((y - yhat)^2)`` over the held-out samples;
   the shrinkage of an effect is ``1 - J_with / J_without`` with ``J_without``
   the re-fit alone, the shrinkage of ``parameter_mismatch`` is
   ``1 - J_refit / J_nominal``. Intervals (95 %) resample the held-out
   segments with replacement (the same draws for every model).
4. **Noise floor** ``sigma^2`` from the re-fit's residual on the evaluated record: the median
   absolute deviation of its second difference, ``sigma = 1.4826 MAD /
   sqrt(6)`` (white measurement noise; slow model errors barely enter a second
   difference and steps are outliers a median ignores). *None*: the nominal
   model's held-out ``J / sigma^2`` is not above ``1 + relevance`` (upper end
   of its interval below, or lower end not above).
5. **Calibration** by parametric bootstrap of the re-fit: ``n_null`` records
   are simulated from the re-fitted model plus white noise of the floor's
   variance, the re-fit is repeated on each, and the held-out shrinkage a
   *perfect* model achieves against that re-fit, ``1 - J_true / J_refit``,
   is recorded. ``calibration="linearized"`` (default) replaces each re-fit
   by its Gauss-Newton step from the re-fit (``J_tr`` the sensitivity of the
   simulated output to the nominal coefficients and the output constant:
   ``delta = lstsq(J_tr, noise_tr)``), exact to first order in the noise, which
   is where a re-fit of a few-% mismatch lives; ``"refit"`` repeats the casadi
   fit on each replicate. Its ``1 - alpha`` quantile is what estimating the nominal
   parameters from noisy data leaves on the table by chance: an effect is
   *significant* when the lower end of its shrinkage interval exceeds it, and
   *relevant* when it also explains at least ``min_share`` of the re-fit's
   held-out excess over the noise floor (the floor taken as at most the
   effect's own held-out ``J``: a model cannot beat the noise on held-out data,
   so one that gets below the floor's estimate shows the estimate is too high,
   and has removed all of the excess that can be measured).
6. **Verdict.** Among the significant, relevant effects the one with the lowest
   held-out ``J`` leads unless a candidate with fewer free parameters (grid,
   factor and basis parameters the fit chose, :func:`_free_parameters`) is not
   beaten significantly by it: the lower end of the interval of its held-out
   shrinkage against that simpler candidate must exceed the calibrated
   threshold, the test every effect passes against the re-fit. Otherwise the
   simplest such candidate leads (``verdict["parsimony"]`` says which one it
   displaced and by how much). ``["parameter_mismatch"]`` if no effect is
   relevant but the re-fit shrinks the gap significantly; ``[]`` when there is
   no gap. Candidates whose held-out ``J`` does not differ from the leader's
   beyond the bootstrap interval and whose held-out outputs differ by less than
   the noise floor's standard deviation are *indistinguishable* from it,
   reported as a group with the experiment that would separate them.

7. **Further effects** (``max_effects``, forward selection): every other candidate
   is screened on top of the accepted effect (:class:`synth.gap.composite.NestedEffect`,
   the accepted effect's parameters fixed), the best two are re-fitted jointly with
   the nominal coefficients, and the better one is accepted when its held-out
   shrinkage against the model before it clears the same calibrated threshold and
   it removes ``min_share`` of that model's excess over the noise floor. The first
   effect is not re-fitted given the second. Lag at the actuator and at
the sensor give the same output on a linear model; the candidate listed first
(``lag``) is reported, the other in its indistinguishable group.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from synth.data.record import Record
from synth.errors import ModelError
from synth.gap.effects.base import Effect, Params
from synth.gap.effects.registry import DEFAULT_CANDIDATES, make_effect
from synth.gap.refit import AugmentedFit, fit_augmented
from synth.gap.screen import ScreenedFit, screen_effect
from synth.gap.stitch import settle_time, stitch_runs
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

SEPARATING_EXPERIMENTS: dict[frozenset[str], str] = {
    frozenset({"delay", "lag"}): "a sweep to higher frequency: a delay's phase keeps falling linearly with "
                                 "frequency, an extra lag's stops at -90 deg",
    frozenset({"lag", "lag(sensor)"}): "log the actuator output (or inject a known excitation at the output): "
                                       "an actuator lag shows in the actuator signal, a sensor lag does not",
    frozenset({"rate_limit", "lag"}): "steps of several amplitudes: a rate limit slows only the large ones, "
                                      "a lag slows all of them in proportion",
    frozenset({"rate_limit", "delay"}): "steps of several amplitudes: a rate limit's lag grows with the step, "
                                        "a delay's does not",
    frozenset({"saturation", "static_nonlinearity"}): "a slow staircase over the whole input range: a "
                                                      "saturation is flat beyond its limit, a smooth map bends",
    frozenset({"saturation", "deadzone"}): "small steps beyond the lowest (or highest) level used so far: a one-sided "
                                           "limit holds them all at one level, a dead zone passes them on shifted",
    frozenset({"deadzone", "backlash"}): "small reversals around one operating point: backlash loses motion "
                                         "at every reversal, a dead zone only near its center",
    frozenset({"drift", "supply_sag"}): "repeat the same step early and late in the run: drift changes the "
                                        "level, sag the transient",
}
"""Experiments that separate two effects the data could not tell apart."""


def _noise_sigma(e: np.ndarray) -> float:
    """Robust white-noise standard deviation from the second difference (MAD)."""
    d2 = np.diff(np.asarray(e, float), 2)
    if d2.size < 3:
        raise ModelError("too few held-out samples to estimate the noise floor", where="record")
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return 1.4826 * mad / np.sqrt(6.0)


def _block_ids(n_held: int, blocks: int) -> np.ndarray:
    edges = np.linspace(0, n_held, blocks + 1).round().astype(int)
    return np.repeat(np.arange(blocks), np.diff(edges))


def _demean(x: np.ndarray, groups: np.ndarray | None = None) -> np.ndarray:
    """``x`` (samples along the first axis) less its mean, per group (run) when ``groups`` is given.

    Examples
    --------
    >>> _demean(np.array([1.0, 3.0, 10.0, 12.0]), np.array([0, 0, 1, 1])).tolist()
    [-1.0, 1.0, -1.0, 1.0]
    """
    if groups is None:
        return x - x.mean(axis=0)
    out = np.array(x, float, copy=True)
    for g in np.unique(groups):
        sel = groups == g
        out[sel] -= out[sel].mean(axis=0)
    return out


def _block_sums(e2: np.ndarray, ids: np.ndarray, blocks: int) -> np.ndarray:
    return np.bincount(ids, weights=e2, minlength=blocks)


@dataclass(frozen=True)
class EffectResult:
    """One candidate effect judged on held-out data.

    Attributes
    ----------
    effect : str
    parameters : dict
        Fitted effect parameters.
    parameter_ci : dict
        Their approximate 95 % intervals (see :mod:`synth.gap.refit`).
    shrinkage : float
        ``1 - J_with / J_without`` on held-out data (``J_without``: the re-fit alone).
    shrinkage_ci : tuple of float
        95 % bootstrap interval over held-out segments.
    significant : bool
        Lower end of ``shrinkage_ci`` above the calibrated threshold.
    share_of_gap : float
        ``(J_nominal - J_with) / (J_nominal - sigma^2)``: part of the nominal model's
        held-out excess over the noise floor this model removes.
    accepted : bool
        In the verdict.
    j_heldout : float
        Held-out mean squared error (output units squared).
    nominal : dict
        Nominal coefficients re-fitted with the effect.
    fit : str
        ``"joint"`` (casadi re-fit with the nominal coefficients) or ``"screened"``
        (denominator fixed, see :mod:`synth.gap.screen`; never accepted).
    """

    effect: str
    parameters: dict[str, float]
    parameter_ci: dict[str, tuple[float, float]]
    shrinkage: float
    shrinkage_ci: tuple[float, float]
    significant: bool
    share_of_gap: float
    accepted: bool
    j_heldout: float
    nominal: dict[str, float]
    fit: str = "joint"

    def to_dict(self) -> dict[str, Any]:
        """JSON entry of ``"effects"``.

        Examples
        --------
        >>> r = EffectResult("delay", {"delay": 0.01}, {"delay": (0.009, 0.011)}, 0.8, (0.7, 0.9), True, 0.8,
        ...                  True, 1.0, {"n0": 2.0})
        >>> r.to_dict()["shrinkage_ci"], r.to_dict()["accepted"]
        ([0.7, 0.9], True)
        """
        return {"effect": self.effect, "parameters": dict(self.parameters),
                "parameter_ci": {k: [float(a), float(b)] for k, (a, b) in self.parameter_ci.items()},
                "shrinkage": self.shrinkage, "shrinkage_ci": [float(x) for x in self.shrinkage_ci],
                "significant": self.significant, "share_of_gap": self.share_of_gap, "accepted": self.accepted,
                "j_heldout": self.j_heldout, "nominal": dict(self.nominal), "fit": self.fit}


@dataclass(frozen=True, eq=False)
class HeldoutSegments:
    """The held-out cost of every model by bootstrap segment (what :mod:`synth.gap.roundrobin` pools).

    Attributes
    ----------
    sums : dict
        ``"nominal"``, ``"refit"`` and each candidate's label -> sum of squared held-out errors per segment.
    counts : numpy.ndarray
        Held-out samples per segment.
    runs : numpy.ndarray
        Validation run (index in the ``validate`` list, 0 for one record) of each segment.
    predictions : dict
        The same labels -> held-out output (offset re-estimated where it is).
    """

    sums: dict[str, np.ndarray]
    counts: np.ndarray
    runs: np.ndarray
    predictions: dict[str, np.ndarray] = field(repr=False)


@dataclass(frozen=True, eq=False)
class EffectDiagnosis:
    """Which effect explains the gap and how far it shrinks on held-out data.

    Attributes
    ----------
    effects : list of EffectResult
        Every candidate, largest shrinkage first.
    verdict : dict
        ``effects`` (accepted, most important first; ``[]`` for none,
        ``["parameter_mismatch"]`` when only the re-fit was needed),
        ``indistinguishable`` (groups), ``experiments`` (one per group),
        ``status``, ``headline`` and ``parsimony`` (``None``, or which candidate with
        fewer parameters leads over the lowest-``J`` one, see :func:`_parsimonious_lead`).
    noise_floor : float
        ``sigma^2`` (output units squared).
    j_nominal, j_refit : float
        Held-out mean squared errors of the nominal model and the re-fit.
    refit_shrinkage, refit_shrinkage_ci
        ``1 - J_refit / J_nominal`` and its interval.
    threshold : float
        Calibrated shrinkage an effect must exceed (parametric bootstrap).
    refit : AugmentedFit
    split : dict
        Training / held-out samples, blocks, bootstrap sizes.
    t, y, y_nominal, y_refit, y_best, heldout
        Held-out-side arrays for the overlay figure (not in ``to_dict``).
    segments : HeldoutSegments
        Every model's held-out segment sums, for pooling several diagnoses (not in ``to_dict``).
    """

    effects: list[EffectResult]
    verdict: dict[str, Any]
    noise_floor: float
    j_nominal: float
    j_refit: float
    refit_shrinkage: float
    refit_shrinkage_ci: tuple[float, float]
    threshold: float
    refit: AugmentedFit
    split: dict[str, Any]
    t: np.ndarray = field(repr=False)
    y: np.ndarray = field(repr=False)
    y_nominal: np.ndarray = field(repr=False)
    y_refit: np.ndarray = field(repr=False)
    y_best: np.ndarray | None = field(repr=False)
    heldout: np.ndarray = field(repr=False)
    segments: HeldoutSegments | None = field(repr=False, default=None)

    def to_dict(self) -> dict[str, Any]:
        """JSON: ``effects``, ``verdict``, noise floor, re-fit, threshold, split.

        Examples
        --------
        >>> import numpy as np
        >>> from synth.data import record_from_arrays
        >>> t = np.arange(0, 8, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
        >>> G = Plant.from_string("2/(0.2*s+1)")
        >>> y = simulate_plant(G, t, u) + 0.01 * np.random.default_rng(1).normal(size=t.size)
        >>> d = diagnose_effects(G, record_from_arrays(t, u, y), candidates=["delay"], n_null=5).to_dict()
        >>> d["verdict"]["effects"], d["verdict"]["status"]
        ([], 'none')
        """
        return {"effects": [e.to_dict() for e in self.effects], "verdict": dict(self.verdict),
                "noise_floor": self.noise_floor, "noise_std": float(np.sqrt(self.noise_floor)),
                "j_nominal": self.j_nominal, "j_refit": self.j_refit,
                "parameter_mismatch": {"shrinkage": self.refit_shrinkage,
                                       "shrinkage_ci": [float(x) for x in self.refit_shrinkage_ci],
                                       "refit": self.refit.to_dict()},
                "threshold": self.threshold, "split": dict(self.split)}


def _experiment(a: str, b: str, t: np.ndarray, ya: np.ndarray, yb: np.ndarray) -> str:
    key = frozenset({a, b})
    if key in SEPARATING_EXPERIMENTS:
        return f"{a} vs {b}: {SEPARATING_EXPERIMENTS[key]}"
    k = int(np.argmax(np.abs(ya - yb)))
    return (f"{a} vs {b}: excite the regime where their outputs differ most (held-out t = {t[k]:.3g} s, "
            f"difference {abs(ya[k] - yb[k]):.3g})")


def diagnose_effects(plant: Plant, record: Record, validate: Record | Sequence[Record] | None = None,
                     candidates: list[str | Effect] | tuple[str, ...] = DEFAULT_CANDIDATES,
                     train_fraction: float = 0.5, blocks: int = 10, n_null: int = 199, n_boot: int = 1000,
                     alpha: float = 0.05, relevance: float = 0.1, min_share: float = 0.25,
                     seed: int = 0, calibration: str = "linearized", confirm: int | None = 3,
                     split: str = "tail", burn_in: float = 0.0, max_effects: int = 2,
                     workers: int = 1, heldout_offset: str = "auto") -> EffectDiagnosis:
    """Attribute the gap between ``plant`` and ``record`` to one effect, and measure its shrinkage.

    Parameters
    ----------
    plant : Plant
        The nominal model (exact delay), driven by the record's input.
    record : Record
        Measured command and output, starting at rest.
    validate : Record or sequence of Record, optional
        Held-out record; without it the record is split (see the module text). Several records
        (runs of the same plant): each is simulated from rest at its own first input (joined by
        settling bridges, :mod:`synth.gap.stitch`), keeps its own held-out offset where offsets are
        fitted, and is cut into its own ``blocks`` segments, resampled within the run (stratified).
    candidates : sequence of str or Effect
        Effects to try (names of :data:`synth.gap.effects.EFFECTS`, or ``"lag(sensor)"``).
    train_fraction : float
        Part of the record used for fitting when there is no validation record.
    blocks : int
        Held-out segments for the bootstrap.
    n_null : int
        Parametric-bootstrap replicates of the re-fit (calibration).
    n_boot : int
        Segment-bootstrap draws (intervals).
    alpha : float
        Level of the calibrated threshold (one-sided).
    relevance : float
        Held-out excess over the noise floor, relative to it, below which there is no gap.
    min_share : float
        Part of the re-fit's held-out excess over noise an effect must remove to be relevant.
    seed : int
        Seed of the bootstrap draws.
    calibration : {"linearized", "refit"}
        How each calibration replicate is re-fitted (see the module text).
    confirm : int or None
        Candidates re-fitted jointly after screening (lowest screened training SSR first);
        ``None``: every candidate, no screening.
    split : {"tail", "interleaved"}
        Without a validation record: ``"tail"`` fits the first ``train_fraction`` and holds out
        the rest; ``"interleaved"`` cuts the record into ``2 blocks`` equal segments and holds out
        every second one (the fits simulate the whole record and count only the training
        segments), for records whose one transient would otherwise fall entirely on one side.
    burn_in : float
        Seconds at the start of the record (and of a validation record) left out of every cost:
        the model starts at rest or in steady state, a record may not (unknown initial state).
    workers : int
        Processes for the joint confirmations (independent casadi fits); 1 runs them in this process.
    heldout_offset : {"auto", "carry", "fit"}
        The output offset on held-out data. ``"carry"``: every model keeps the offset fitted on the
        training data. ``"fit"``: each model's offset is re-estimated on the held-out samples (the mean
        of its held-out residual; the calibration removes it likewise): a validation record from
        another run has its own operating point and sensor zero, which say nothing about the
        dynamics. ``"auto"``: ``"fit"`` with a validation record, ``"carry"`` for a split record.
    max_effects : int
        Effects a verdict may name. After the first, forward selection: every other significant
        candidate is fitted on top of the accepted one (:class:`synth.gap.composite.NestedEffect`,
        nominal coefficients re-fitted jointly again) and accepted when it shrinks the held-out
        error of the model with the effects before it beyond the same calibrated threshold and
        removes at least ``min_share`` of that model's excess over the noise floor.

    Returns
    -------
    EffectDiagnosis

    Raises
    ------
    ModelError
        Bad options, unknown candidates, or too few samples.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 12, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(0.2*s+1)", delay=0.05), t, u)
    >>> y = y + 0.005 * np.random.default_rng(0).normal(size=t.size)
    >>> dg = diagnose_effects(Plant.from_string("2.1/(0.2*s+1)"), record_from_arrays(t, u, y),
    ...                       candidates=["delay"], n_null=5)
    >>> dg.verdict["effects"], round(dg.effects[0].parameters["delay"], 3), dg.effects[0].shrinkage > 0.9
    (['delay'], 0.05, True)
    """
    if not 0.1 <= train_fraction <= 0.9:
        raise ModelError(f"must be in [0.1, 0.9], got {train_fraction!r}", where="train_fraction")
    if blocks < 3 or n_null < 1 or n_boot < 10:
        raise ModelError("need blocks >= 3, n_null >= 1 and n_boot >= 10", where="diagnose_effects")
    if calibration not in ("linearized", "refit"):
        raise ModelError(f"must be 'linearized' or 'refit', got {calibration!r}", where="calibration")
    if confirm is not None and confirm < 1:
        raise ModelError(f"must be None or >= 1, got {confirm!r}", where="confirm")
    if max_effects < 1:
        raise ModelError(f"must be >= 1, got {max_effects!r}", where="max_effects")
    if heldout_offset not in ("auto", "carry", "fit"):
        raise ModelError(f"must be 'auto', 'carry' or 'fit', got {heldout_offset!r}", where="heldout_offset")
    runs: list[Record] | None = list(validate) if isinstance(validate, (list, tuple)) else None
    if runs is not None and len(runs) < 2:
        validate, runs = (runs[0] if runs else None), None
    fit_offset = heldout_offset == "fit" or (heldout_offset == "auto" and validate is not None)
    if split not in ("tail", "interleaved"):
        raise ModelError(f"must be 'tail' or 'interleaved', got {split!r}", where="split")
    if not (np.isfinite(burn_in) and burn_in >= 0.0):
        raise ModelError(f"must be a number of seconds >= 0, got {burn_in!r}", where="burn_in")
    effects = [make_effect(c) for c in candidates]
    labels = [e.label for e in effects]
    if len(set(labels)) != len(labels):
        raise ModelError(f"repeated candidates in {labels}", where="candidates")
    rng = np.random.default_rng(seed)
    train_mask: np.ndarray | None = None
    if validate is None and split == "tail":
        k = round(train_fraction * record.n)
        t_tr, u_tr, y_tr = record.t[:k], record.u[:k], record.y[:k]
        t_ev, u_ev, y_ev = record.t, record.u, record.y
        held = np.arange(record.n) >= k
    elif validate is None:  # interleaved: odd segments held out, the fits count the even ones
        t_tr, u_tr, y_tr = record.t, record.u, record.y
        t_ev, u_ev, y_ev = record.t, record.u, record.y
        held = _block_ids(record.n, 2 * blocks) % 2 == 1
        train_mask = ~held
    elif runs is None:
        t_tr, u_tr, y_tr = record.t, record.u, record.y
        t_ev, u_ev, y_ev = validate.t, validate.u, validate.y
        held = np.ones(validate.n, bool)
    else:
        t_tr, u_tr, y_tr = record.t, record.u, record.y
        joined = stitch_runs(runs, settle_time(plant))
        t_ev, u_ev, y_ev = joined.t, joined.u, joined.y
        held = joined.run >= 0
    if burn_in > 0.0:
        settled_tr = t_tr >= t_tr[0] + burn_in
        train_mask = settled_tr if train_mask is None else train_mask & settled_tr
        held = held & ((t_ev >= t_ev[0] + burn_in) if runs is None else (np.nan_to_num(joined.since_start,
                                                                                         nan=-1.0) >= burn_in))
        if int(train_mask.sum()) < 20:
            raise ModelError(f"a burn-in of {burn_in:g} s leaves too few training samples", where="burn_in")
    n_held = int(held.sum())
    groups = None if runs is None else joined.run[held]  # the held-out run of each held-out sample
    for r in range(1 if runs is None else len(runs)):
        n_r = n_held if groups is None else int(np.sum(groups == r))
        if n_r < 10 * blocks:
            where = "record" if runs is None else f"validate run {r + 1}"
            raise ModelError(f"{n_r} held-out samples are too few for {blocks} segments", where=where)
    if groups is None:
        ids = _block_ids(n_held, blocks)
        draws = rng.integers(0, blocks, size=(n_boot, blocks))
        n_blocks = blocks
    else:  # each run its own segments, resampled within the run
        ids = np.concatenate([_block_ids(int(np.sum(groups == r)), blocks) + r * blocks for r in range(len(runs))])
        draws = np.concatenate([rng.integers(0, blocks, size=(n_boot, blocks)) + r * blocks
                                for r in range(len(runs))], axis=1)
        n_blocks = blocks * len(runs)
    counts = np.bincount(ids, minlength=n_blocks).astype(float)
    boot_n = counts[draws].sum(axis=1)

    def sums(yhat: np.ndarray) -> np.ndarray:
        e = y_ev[held] - yhat[held]
        return _block_sums(_demean(e, groups) ** 2 if fit_offset else e**2, ids, n_blocks)

    def shifted(yhat: np.ndarray | None) -> np.ndarray | None:
        """A prediction with its held-out offset re-estimated (as judged), for the figures."""
        if yhat is None or not fit_offset:
            return yhat
        out = yhat.copy()
        e = (y_ev - yhat)[held]
        out[held] += e - _demean(e, groups)
        if groups is None:
            out[~held] += float(np.mean(e))
        return out

    def boot(s: np.ndarray) -> np.ndarray:
        return s[draws].sum(axis=1) / boot_n

    def ratio_ci(num: np.ndarray, den: np.ndarray) -> tuple[float, float]:
        r = 1.0 - boot(num) / boot(den)
        return float(np.quantile(r, 0.025)), float(np.quantile(r, 0.975))

    def diff_ci(s_a: np.ndarray, s_b: np.ndarray) -> tuple[float, float]:
        """95 % interval of ``(J_a - J_b) / J_refit`` (the same segment draws for both models)."""
        d = (boot(s_a) - boot(s_b)) / boot(s_ref)
        return float(np.quantile(d, 0.025)), float(np.quantile(d, 0.975))

    fitted = slice(None) if train_mask is None else train_mask
    c_nom = float(np.mean((y_tr - simulate_plant(plant, t_tr, u_tr))[fitted]))
    y_nom = simulate_plant(plant, t_ev, u_ev) + c_nom
    weights = None if train_mask is None else train_mask.astype(float)
    refit = fit_augmented(plant, t_tr, u_tr, y_tr, weights=weights)
    y_ref = refit.predict(t_ev, u_ev)
    s_nom, s_ref = sums(y_nom), sums(y_ref)
    j_nom, j_ref = float(s_nom.sum() / n_held), float(s_ref.sum() / n_held)
    settled = (t_ev >= t_ev[0] + burn_in) if runs is None else held
    sigma = _noise_sigma((y_ev - y_ref)[settled])  # every settled sample of the evaluated record (same white noise)
    floor = sigma**2
    pm_shrink = 1.0 - j_ref / j_nom if j_nom > 0 else 0.0
    pm_ci = ratio_ci(s_ref, s_nom)
    excess_nom = boot(s_nom) / floor - 1.0
    excess_ref = boot(s_ref) / floor - 1.0
    gap_present = float(np.quantile(excess_nom, 0.025)) > relevance
    gap_after_refit = float(np.quantile(excess_ref, 0.025)) > relevance

    # calibration: parametric bootstrap of the re-fit
    if calibration == "linearized":
        null = _linearized_null(refit, t_tr, u_tr, t_ev, u_ev, held, validate is None, sigma, n_null, rng,
                                train_mask, fit_offset, groups)
    else:
        null = _refit_null(refit, t_tr, u_tr, t_ev, u_ev, held, validate is None, sigma, n_null, rng, train_mask,
                           fit_offset, groups)
    threshold = float(np.quantile(null, 1.0 - alpha, method="higher"))

    fits = _candidate_fits(plant, effects, refit, t_tr, u_tr, y_tr, t_ev, u_ev, confirm, train_mask, workers)

    by_label = {eff.label: (eff, fit) for eff, fit, _, _ in fits}
    results: list[tuple[EffectResult, np.ndarray, np.ndarray]] = []
    for eff, fit, _, yhat in fits:
        s = sums(yhat)
        j = float(s.sum() / n_held)
        shrink = 1.0 - j / j_ref if j_ref > 0 else 0.0
        ci = ratio_ci(s, s_ref)
        share = (j_nom - j) / (j_nom - floor) if j_nom > floor else 0.0
        share_ref = _share_of_excess(j_ref, j, floor)
        significant = bool(gap_present and ci[0] > threshold)
        joint = isinstance(fit, AugmentedFit)
        relevant = bool(significant and share_ref >= min_share and joint)
        params = {k: float(fit.params[k]) for k in eff.parameter_names}
        p_ci = fit.parameter_ci if joint else {}
        nominal = dict(fit.nominal) if joint else _coefficients(fit.plant)
        res = EffectResult(eff.label, params, p_ci, shrink, ci, significant, float(share), relevant, j, nominal,
                           "joint" if joint else "screened")
        results.append((res, yhat, s))
    segments = HeldoutSegments({"nominal": s_nom, "refit": s_ref, **{r.effect: s for r, _, s in results}}, counts,
                               np.arange(n_blocks) // blocks,
                               {"nominal": shifted(y_nom)[held], "refit": shifted(y_ref)[held],
                                **{r.effect: shifted(y)[held] for r, y, _ in results}})
    results.sort(key=lambda r: (-r[0].shrinkage, r[0].fit != "joint"))

    relevant = [r for r in results if r[0].accepted]
    indist: list[list[str]] = []
    experiments: list[str] = []
    y_best = None
    parsimony: dict[str, Any] | None = None
    if not gap_present:
        verdict_effects: list[str] = []
        status = "none"
    elif relevant:
        counts = [_free_parameters(by_label[r.effect][0], r.parameters) for r, _, _ in relevant]
        lead, parsimony = _parsimonious_lead([(r.effect, s) for r, _, s in relevant], counts, ratio_ci, threshold)
        best, y_best, s_best = relevant[lead]
        verdict_effects = [best.effect]
        status = "effect"
        group = [best.effect]
        for res, yhat, s in results:
            if res.effect == best.effect or not res.significant:
                continue
            d_lo, d_hi = diff_ci(s, s_best)
            same_j = d_lo <= 0.0 <= d_hi
            gap_ab = (yhat - y_best)[held]
            rms_diff = float(np.sqrt(np.mean((_demean(gap_ab, groups) if fit_offset else gap_ab) ** 2)))
            close = rms_diff < sigma
            # outputs a tenth of the noise apart: any difference in J is the noise's, whatever the bootstrap says
            same_j = same_j or rms_diff < 0.1 * sigma
            if same_j and close:
                group.append(res.effect)
                experiments.append(_experiment(best.effect, res.effect, t_ev[held], y_best[held], yhat[held]))
        if len(group) > 1:
            indist.append(group)
        results = [(r if r.effect == best.effect else _unaccept(r), y, s) for r, y, s in results]
        chain = _Chain(plant, t_tr, u_tr, y_tr, t_ev, u_ev, weights, train_mask, sums, ratio_ci, threshold, min_share,
                       floor, n_held, workers)
        eff_best, fit_best = by_label[best.effect]
        tried = {best.effect, *group}
        while len(verdict_effects) < max_effects:
            pool = [eff for eff in effects if eff.label not in tried]
            step = chain.next(eff_best, fit_best, s_best, pool)
            if step is None:
                break
            nested, fit2, res2, y2, s2 = step
            results.append((res2, y2, s2))
            tried.add(res2.effect.split("+")[-1])
            if not res2.accepted:
                break
            verdict_effects.append(res2.effect.split("+")[-1])
            eff_best, fit_best, s_best, y_best = nested, fit2, s2, y2
    elif pm_ci[0] > 0.0:
        verdict_effects = ["parameter_mismatch"]
        status = "unexplained" if gap_after_refit else "parameter_mismatch"
    else:
        verdict_effects = []
        status = "unexplained"
    headline = _headline(status, verdict_effects, indist, results, pm_shrink, j_nom, floor)
    verdict = {"effects": verdict_effects, "indistinguishable": indist, "experiments": experiments,
               "status": status, "headline": headline, "parsimony": parsimony}
    n_train = int(t_tr.size if train_mask is None else train_mask.sum())
    mode = split if validate is None else "validation"
    split = {"train_samples": n_train, "heldout_samples": n_held, "blocks": blocks, "n_null": n_null,
             "n_boot": n_boot, "alpha": alpha, "validation_record": validate is not None, "seed": seed,
             "calibration": calibration, "confirm": confirm, "split": mode,
             "burn_in": burn_in, "heldout_offset": "fit" if fit_offset else "carry",
             "validation_runs": 1 if runs is None else len(runs),
             "joint_fits": [r.effect for r, _, _ in results if r.fit == "joint"]}
    return EffectDiagnosis([r for r, _, _ in results], verdict, floor, j_nom, j_ref, pm_shrink, pm_ci, threshold,
                           refit, split, t_ev, y_ev, shifted(y_nom), shifted(y_ref), shifted(y_best), held, segments)


@dataclass(frozen=True)
class _Folded:
    """``first`` (an extra delay) folded into the linear model, ``second`` fitted alone on top of it."""

    first: Effect
    second: Effect

    @property
    def label(self) -> str:
        return f"{self.first.label}+{self.second.label}"


class _Chain:
    """Forward selection: the best further effect on top of the accepted ones, judged on held-out data."""

    def __init__(self, plant: Plant, t_tr: np.ndarray, u_tr: np.ndarray, y_tr: np.ndarray, t_ev: np.ndarray,
                 u_ev: np.ndarray, weights: np.ndarray | None, train_mask: np.ndarray | None, sums: Any,
                 ratio_ci: Any, threshold: float, min_share: float, floor: float, n_held: int,
                 workers: int = 1) -> None:
        self.plant, self.t_tr, self.u_tr, self.y_tr, self.t_ev, self.u_ev = plant, t_tr, u_tr, y_tr, t_ev, u_ev
        self.weights, self.train_mask, self.sums, self.ratio_ci = weights, train_mask, sums, ratio_ci
        self.threshold, self.min_share, self.floor, self.n_held = threshold, min_share, floor, n_held
        self.workers = workers

    def next(self, eff_a: Effect, fit_a: AugmentedFit, s_a: np.ndarray, pool: list[Effect],
             keep: int = 2) -> tuple[Effect, AugmentedFit, EffectResult, np.ndarray, np.ndarray] | None:
        """Screen every effect of ``pool`` on top of ``eff_a``, re-fit the best ``keep`` jointly, judge the best."""
        from synth.gap.composite import NestedEffect

        fixed = {k: float(v) for k, v in fit_a.params.items()}
        base_plant = fit_a.plant
        folded = eff_a.folds_into_plant  # an extra delay folds into the linear model: B alone on top of it
        if folded:
            base_plant = fit_a.plant.with_delay(fit_a.plant.delay + fixed.get("delay", 0.0))
        screened: list[tuple[Effect, ScreenedFit | None]] = []
        for eff_b in pool:
            try:
                nested = _Folded(eff_a, eff_b) if folded else NestedEffect(eff_a, fixed, eff_b)
                bases = [("accepted", base_plant)]
                model = nested.second if folded else nested
                sc = screen_effect(model, bases, self.t_tr, self.u_tr, self.y_tr, self.t_ev, self.u_ev,
                                   self.train_mask) if model.screenable else None
            except ModelError:
                continue
            screened.append((nested, sc))
        screened.sort(key=lambda es: es[1].ssr if es[1] is not None else -np.inf)
        best: tuple[Effect, AugmentedFit, np.ndarray, np.ndarray] | None = None
        jobs = []
        for nested, sc in screened[:keep]:
            model = nested.second if folded else nested
            grid = _seeded(model, sc, self.u_tr) if sc is not None else None
            jobs.append((base_plant if folded else self.plant, self.t_tr, self.u_tr, self.y_tr, model, base_plant,
                         self.weights, grid))
        for (nested, _), fit in zip(screened[:keep], _map(_joint_fit, jobs, self.workers)):
            if fit is None:
                continue
            yhat = fit.predict(self.t_ev, self.u_ev)
            s = self.sums(yhat)
            if np.isfinite(s.sum()) and (best is None or s.sum() < best[3].sum()):
                best = (nested, fit, yhat, s)
        if best is None:
            return None
        nested, fit, yhat, s = best
        j_a, j = float(s_a.sum() / self.n_held), float(s.sum() / self.n_held)
        ci = self.ratio_ci(s, s_a)
        share = _share_of_excess(j_a, j, self.floor)
        significant = bool(ci[0] > self.threshold)
        accepted = bool(significant and share >= self.min_share)
        second = nested.second
        params = {k: float(fit.params[k]) for k in second.parameter_names}
        res = EffectResult(nested.label, params, dict(fit.parameter_ci), 1.0 - j / j_a if j_a > 0 else 0.0, ci,
                           significant, float(share), accepted, j, dict(fit.nominal), "joint")
        return nested, fit, res, yhat, s


def _coefficients(plant: Plant) -> dict[str, float]:
    from synth.gap.refit import nominal_structure

    return nominal_structure(plant)[1] | {"delay": plant.delay}


def _sensitivity(plant: Plant, t: np.ndarray, u: np.ndarray) -> np.ndarray:
    """d(simulated output)/d(each nonzero coefficient, monic denominator) and d/d(offset), central differences."""
    cols = []
    for which in ("num", "den"):
        base = getattr(plant, which)
        for i, c in enumerate(base):
            if c == 0.0 or (which == "den" and i == 0):
                continue
            h = 1e-6 * max(abs(c), 1e-8)
            out = []
            for sgn in (1.0, -1.0):
                arr = base.astype(float).copy()
                arr[i] += sgn * h
                num, den = (arr, plant.den) if which == "num" else (plant.num, arr)
                out.append(simulate_plant(Plant(num, den, plant.delay), t, u))
            cols.append((out[0] - out[1]) / (2 * h))
    cols.append(np.ones_like(t))
    return np.column_stack(cols)


def _linearized_null(refit: AugmentedFit, t_tr: np.ndarray, u_tr: np.ndarray, t_ev: np.ndarray, u_ev: np.ndarray,
                     held: np.ndarray, split: bool, sigma: float, n_null: int,
                     rng: np.random.Generator, train_mask: np.ndarray | None = None,
                     fit_offset: bool = False, groups: np.ndarray | None = None) -> np.ndarray:
    """Held-out shrinkage of a perfect model against the re-fit, re-fit linearized (Gauss-Newton step).

    ``split``: the training record is the start of the evaluated one; ``train_mask``: the training
    samples that count in the fit's cost (default all); ``fit_offset``: both held-out residuals have
    their mean removed (the offset re-estimated on held-out data), per run with ``groups``.
    """
    J_ev = _sensitivity(refit.plant, t_ev, u_ev)
    J_tr = J_ev[:t_tr.size] if split else _sensitivity(refit.plant, t_tr, u_tr)
    if train_mask is not None:
        J_tr = J_tr[train_mask]
    n_tr = sigma * rng.standard_normal((J_tr.shape[0], n_null))
    scale = np.maximum(np.sqrt(np.sum(J_tr**2, axis=0)), 1e-300)
    delta = np.linalg.lstsq(J_tr / scale, n_tr, rcond=None)[0] / scale[:, None]
    noise = sigma * rng.standard_normal((int(held.sum()), n_null))
    e_fit = noise - J_ev[held] @ delta
    if fit_offset:
        noise, e_fit = _demean(noise, groups), _demean(e_fit, groups)
    return 1.0 - np.mean(noise**2, axis=0) / np.mean(e_fit**2, axis=0)


def _refit_null(refit: AugmentedFit, t_tr: np.ndarray, u_tr: np.ndarray, t_ev: np.ndarray, u_ev: np.ndarray,
                held: np.ndarray, split: bool, sigma: float, n_null: int, rng: np.random.Generator,
                train_mask: np.ndarray | None = None, fit_offset: bool = False,
                groups: np.ndarray | None = None) -> np.ndarray:
    """The same with the casadi re-fit repeated on every replicate."""
    null = []
    y_ref = refit.predict(t_ev, u_ev)
    y_ref_tr = refit.predict(t_tr, u_tr)
    weights = None if train_mask is None else train_mask.astype(float)
    for _ in range(n_null):
        n_tr = sigma * rng.standard_normal(t_tr.size)
        noise = np.r_[n_tr, sigma * rng.standard_normal(t_ev.size - t_tr.size)] if split else \
            sigma * rng.standard_normal(t_ev.size)
        fit_b = fit_augmented(refit.plant, t_tr, u_tr, y_ref_tr + n_tr, weights=weights)
        e_fit, e_true = (y_ref + noise - fit_b.predict(t_ev, u_ev))[held], noise[held]
        if fit_offset:
            e_fit, e_true = _demean(e_fit, groups), _demean(e_true, groups)
        j_fit, j_true = float(np.mean(e_fit**2)), float(np.mean(e_true**2))
        null.append(1.0 - j_true / j_fit)
    return np.asarray(null)


def _seeded(effect: Effect, screened: ScreenedFit, u_train: np.ndarray | None = None) -> list[Params]:
    """The joint fit's search grid: the screened point and its neighbours (+-15 % in the key)."""
    point = {k: v for k, v in screened.params.items() if k not in effect.basis_names}
    return effect.seed_grid(point, u_train)


def _candidate_fits(plant: Plant, effects: list[Effect], refit: AugmentedFit, t_tr: np.ndarray, u_tr: np.ndarray,
                    y_tr: np.ndarray, t_ev: np.ndarray, u_ev: np.ndarray, confirm: int | None,
                    train_mask: np.ndarray | None = None, workers: int = 1,
                    ) -> list[tuple[Effect, AugmentedFit | ScreenedFit, np.ndarray, np.ndarray]]:
    """Every candidate's fit: joint for all (``confirm=None``) or screened, the best ``confirm`` then joint.

    Effects the screen cannot represent (``Effect.screenable`` false: friction, output-side clipping) are
    always fitted jointly.
    """
    out: list[tuple[Effect, AugmentedFit | ScreenedFit, np.ndarray, np.ndarray]] = []
    weights = None if train_mask is None else train_mask.astype(float)
    if confirm is None:
        for eff in effects:
            try:
                fit = fit_augmented(plant, t_tr, u_tr, y_tr, eff, start=refit.plant, weights=weights)
            except ModelError:
                continue
            out.append((eff, fit, fit.predict(t_tr, u_tr), fit.predict(t_ev, u_ev)))
        return out
    bases = [("nominal", plant), ("refit", refit.plant)]
    screened: list[tuple[Effect, ScreenedFit]] = []
    for eff in effects:
        if not eff.screenable:  # the screen holds the input fixed and has no output map: fit these jointly
            try:
                fit = fit_augmented(plant, t_tr, u_tr, y_tr, eff, start=refit.plant, weights=weights)
            except ModelError:
                continue
            out.append((eff, fit, fit.predict(t_tr, u_tr), fit.predict(t_ev, u_ev)))
            continue
        try:
            screened.append((eff, screen_effect(eff, bases, t_tr, u_tr, y_tr, t_ev, u_ev, train_mask)))
        except ModelError:
            continue
    screened.sort(key=lambda es: es[1].ssr)
    chosen = _confirmed(screened, confirm)
    jobs = []
    for i in chosen:
        eff, sc = screened[i]
        if i >= (confirm or 0) and sc.params_held:  # confirmed for its held-denominator fit: start there
            sc = replace(sc, params=sc.params_held)
        jobs.append((plant, t_tr, u_tr, y_tr, eff, refit.plant, weights, _seeded(eff, sc, u_tr)))
    joints = dict(zip(chosen, _map(_joint_fit, jobs, workers)))
    for rank, (eff, sc) in enumerate(screened):
        fit: AugmentedFit | ScreenedFit = sc
        joint = joints.get(rank)
        if joint is not None and np.isfinite(joint.ssr):  # the exact model (the screen's SSR is linearized)
            fit = joint
        if isinstance(fit, AugmentedFit):
            out.append((eff, fit, fit.predict(t_tr, u_tr), fit.predict(t_ev, u_ev)))
        else:
            out.append((eff, fit, sc.yhat_train, sc.yhat_eval))
    return out


def _confirmed(screened: list[tuple[Effect, ScreenedFit]], confirm: int) -> list[int]:
    """Which screened candidates (sorted by screened SSR) are re-fitted jointly: the best ``confirm``,
    and the best with the denominator held exactly if it is not among them.

    The screen's Gauss-Newton step in the denominator is linearized: when the gap is large it lets
    every candidate reach about the same SSR, effect or no effect, and the ranking among them is
    noise. With the denominator held, only an effect that explains the gap gets far; it is
    confirmed too (one more joint fit at most).

    Examples
    --------
    >>> from types import SimpleNamespace as S
    >>> sc = [(None, S(ssr=1.0, ssr_held=9.0)), (None, S(ssr=1.1, ssr_held=8.0)), (None, S(ssr=1.2, ssr_held=2.0))]
    >>> _confirmed(sc, 2), _confirmed(sc, 3), _confirmed(sc, 1)
    ([0, 1, 2], [0, 1, 2], [0, 2])
    """
    chosen = list(range(min(confirm, len(screened))))
    held = [i for i in range(len(screened)) if np.isfinite(screened[i][1].ssr_held)]
    if held:
        best = min(held, key=lambda i: screened[i][1].ssr_held)
        if best not in chosen:
            chosen.append(best)
    return chosen


def _joint_fit(job: tuple[Any, ...]) -> AugmentedFit | None:
    """One confirmation: the joint re-fit of an effect on its seeded grid (``None`` if no point could be fitted)."""
    plant, t, u, y, eff, start, weights, grid = job
    try:
        return fit_augmented(plant, t, u, y, eff, start=start, weights=weights, grid=grid)
    except ModelError:
        return None


def _map(fn: Any, jobs: list[Any], workers: int) -> list[Any]:
    """``[fn(j) for j in jobs]``, on ``workers`` processes when there are several jobs."""
    if workers <= 1 or len(jobs) <= 1:
        return [fn(j) for j in jobs]
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=min(workers, len(jobs))) as pool:
        return list(pool.map(fn, jobs))


def _share_of_excess(j_before: float, j: float, floor: float) -> float:
    """Part of a model's held-out excess over the noise floor that a model with held-out ``J = j`` removes.

    The floor is taken as at most ``j``: the noise variance is no larger than the held-out error of
    a model of the record (its expectation is the noise variance plus the model's error), so a model
    that gets below the floor's estimate shows that the estimate is too high there, and removes all
    of the excess that can be measured.

    Parameters
    ----------
    j_before : float
        Held-out ``J`` of the model before (the re-fit, or the model with the accepted effects).
    j : float
        Held-out ``J`` of the model judged.
    floor : float
        Noise floor ``sigma^2`` (robust estimate, see the module text).

    Returns
    -------
    float
        ``(j_before - j) / (j_before - min(floor, j))``; 0 when ``j_before`` is not above that floor.

    Examples
    --------
    >>> round(_share_of_excess(2.0, 1.5, 1.0), 3), _share_of_excess(0.95, 0.85, 1.0)
    (0.5, 1.0)
    >>> _share_of_excess(0.95, 0.97, 1.0)
    0.0
    """
    base = min(floor, j)
    return (j_before - j) / (j_before - base) if j_before > base else 0.0


def _free_parameters(effect: Effect, params: dict[str, float]) -> int:
    """Parameters the fit of ``effect`` chose: its grid, factor and basis parameters with a finite value.

    A parameter the effect fixes from the record (a dead zone's center, the static map's center and
    scale) is not chosen by the fit, and a limit left at infinity (the unused side of a one-sided
    saturation) is not a parameter of the fitted model. An effect that declares no grid, factor or
    basis parameters counts its ``parameter_names``.

    Examples
    --------
    >>> from synth.gap.effects import make_effect
    >>> _free_parameters(make_effect("resonance"), {"wn": 80.0, "zeta": 0.3})
    2
    >>> _free_parameters(make_effect("saturation"), {"lower": 2.4, "upper": float("inf")})
    1
    >>> _free_parameters(make_effect("deadzone"), {"width": 0.1, "center": 2.0})
    1
    """
    names = tuple(dict.fromkeys((*effect.grid_names, *effect.factor_names, *effect.basis_names)))
    return sum(1 for name in names or effect.parameter_names if np.isfinite(params.get(name, np.nan)))


def _parsimonious_lead(candidates: list[tuple[str, np.ndarray]], counts: list[int], advantage_ci: Any,
                       threshold: float) -> tuple[int, dict[str, Any] | None]:
    """Which accepted candidate leads the verdict: the simplest one the best does not beat significantly.

    Parameters
    ----------
    candidates : list of (str, numpy.ndarray)
        The relevant candidates' labels and held-out block sums, lowest held-out ``J`` first.
    counts : list of int
        Their free parameters (:func:`_free_parameters`).
    advantage_ci : callable
        ``advantage_ci(s_a, s_b)``: 95 % bootstrap interval of the held-out shrinkage ``1 - J_a / J_b``
        of model ``a`` against model ``b`` (the same segment draws for both).
    threshold : float
        The calibrated shrinkage an effect must exceed against the re-fit (parametric bootstrap).

    Returns
    -------
    int
        Index of the leader in ``candidates``.
    dict or None
        ``{"lead", "lead_parameters", "best", "best_parameters", "advantage_ci", "threshold"}`` when the
        leader is not the lowest-``J`` candidate (``advantage_ci``: the interval of the best's shrinkage
        against the leader), else ``None``.

    Notes
    -----
    A model with more free parameters also fits the training noise better and carries some of that
    to held-out data by chance. It leads a simpler accepted candidate only when its held-out
    shrinkage against that candidate passes the test every effect passes against the re-fit: the
    lower end of its interval above the calibrated threshold. Among the candidates the best does not
    beat so, the one with the fewest parameters leads (ties: the lower held-out ``J``).

    Examples
    --------
    >>> ci = lambda a, b: (1 - a.sum() / b.sum() - 0.01, 1 - a.sum() / b.sum() + 0.01)  # +-0.01 interval
    >>> two, one = ("resonance", np.array([10.0])), ("delay", np.array([10.1]))
    >>> _parsimonious_lead([two, one], [2, 1], ci, 0.02)[0]  # 1 % better: not significant, the delay leads
    1
    >>> _parsimonious_lead([two, ("delay", np.array([13.0]))], [2, 1], ci, 0.02)  # 23 % better: resonance
    (0, None)
    """
    s_best = candidates[0][1]
    lead = 0
    for i in range(1, len(candidates)):
        if counts[i] < counts[lead] and advantage_ci(s_best, candidates[i][1])[0] <= threshold:
            lead = i
    if lead == 0:
        return 0, None
    return lead, {"lead": candidates[lead][0], "lead_parameters": counts[lead], "best": candidates[0][0],
                  "best_parameters": counts[0], "advantage_ci": list(advantage_ci(s_best, candidates[lead][1])),
                  "threshold": threshold}


def _unaccept(r: EffectResult) -> EffectResult:
    from dataclasses import replace

    return replace(r, accepted=False)


def _headline(status: str, effects: list[str], indist: list[list[str]], results: list[Any], pm: float,
              j_nom: float, floor: float) -> str:
    if status == "none":
        return (f"no gap: the nominal model's held-out error is within the noise floor "
                f"(J/sigma^2 = {j_nom / floor:.2f})")
    if status == "effect":
        best = next(r for r, _, _ in results if r.effect == effects[0])
        text = (f"{best.effect}: held-out shrinkage {best.shrinkage:.2f} "
                f"[{best.shrinkage_ci[0]:.2f}, {best.shrinkage_ci[1]:.2f}] beyond the re-fit, "
                f"{100 * best.share_of_gap:.0f} % of the gap above noise")
        if indist:
            text += "; not separable from " + ", ".join(indist[0][1:])
        return text
    if status == "parameter_mismatch":
        return f"parameter mismatch: re-fitting the nominal coefficients shrinks the held-out error by {pm:.2f}"
    return "gap not explained by the candidate effects" + (
        f" (the re-fit shrinks it by {pm:.2f})" if effects else "")
