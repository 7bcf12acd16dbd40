"""Which effect closes the gap, and how far: nested augmentations judged on held-out data.

Procedure (:func:`diagnose_effects`, options :class:`DiagnoseOptions`)
--------------------------------------------------------------------
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
   coefficients re-fitted jointly (:func:`synth.gap.attribution.refit.fit_augmented`).
   With ``confirm=k`` every candidate is first *screened*
   (:mod:`synth.gap.attribution.screen`: the denominator held at the nominal's or the
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
   and has removed all of the excess that can be measured), and when its held-out ``J`` is below the
   nominal model's too (a re-fit that made the held-out error worse is no baseline to explain the gap by).
6. **Verdict.** Among the significant, relevant effects the one with the lowest
   held-out ``J`` leads unless a candidate with fewer free parameters (grid,
   factor and basis parameters the fit chose, :func:`synth.gap.attribution.parsimony.free_parameters`) is not
   beaten significantly by it: the lower end of the interval of its held-out
   shrinkage against that simpler candidate must exceed the calibrated
   threshold, the test every effect passes against the re-fit. Otherwise the
   simplest such candidate leads (``verdict["parsimony"]`` says which one it
   displaced and by how much). ``["parameter_mismatch"]`` if no effect is
   relevant but the re-fit shrinks the gap significantly; ``[]`` when there is
   no gap. Candidates whose held-out ``J`` does not differ from the leader's
   beyond the bootstrap interval, or whose held-out outputs differ by less than
   a tenth of the noise floor's standard deviation, are *indistinguishable* from it,
   reported as a group with the experiment that would separate them.

7. **Further effects** (``max_effects``, forward selection): every other candidate
   is screened on top of the accepted effect (:class:`synth.gap.attribution.composite.NestedEffect`,
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
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from synth.data.record import Record
from synth.errors import ModelError
from synth.gap.attribution.calibration import demean, linearized_null, noise_sigma, refit_null
from synth.gap.attribution.candidates import advance, candidate_fits, screened_coefficients
from synth.gap.attribution.forward import ForwardSelection
from synth.gap.attribution.parsimony import free_parameters, parsimonious_lead, share_of_excess
from synth.gap.attribution.physical import wrong_sign
from synth.gap.attribution.refit import AugmentedFit, fit_augmented
from synth.gap.attribution.split import block_ids, split_heldout
from synth.gap.attribution.verdict import (
    EffectDiagnosis,
    EffectResult,
    HeldoutSegments,
    headline,
    separating_experiment,
)
from synth.gap.effects.base import Effect
from synth.gap.effects.registry import DEFAULT_CANDIDATES, make_effect
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["DiagnoseOptions", "diagnose_effects"]


def _block_sums(e2: np.ndarray, ids: np.ndarray, blocks: int) -> np.ndarray:
    return np.bincount(ids, weights=e2, minlength=blocks)


@dataclass(frozen=True)
class DiagnoseOptions:
    """How :func:`diagnose_effects` fits and judges the candidates (every field has its default).

    Attributes
    ----------
    candidates : sequence of str or Effect
        Effects to try (names of :data:`synth.gap.effects.registry.EFFECTS`, or ``"lag(sensor)"``;
        default :data:`synth.gap.effects.registry.DEFAULT_CANDIDATES`).
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
        candidate is fitted on top of the accepted one (:class:`synth.gap.attribution.composite.NestedEffect`,
        nominal coefficients re-fitted jointly again) and accepted when it shrinks the held-out
        error of the model with the effects before it beyond the same calibrated threshold and
        removes at least ``min_share`` of that model's excess over the noise floor.

    Raises
    ------
    ModelError
        A bad option (one line naming it).

    Examples
    --------
    >>> DiagnoseOptions().n_null, DiagnoseOptions(confirm=None).confirm
    (199, None)
    >>> DiagnoseOptions(split="random")
    Traceback (most recent call last):
    synth.errors.ModelError: split: must be 'tail' or 'interleaved', got 'random'
    """

    candidates: Sequence[str | Effect] = DEFAULT_CANDIDATES
    train_fraction: float = 0.5
    blocks: int = 10
    n_null: int = 199
    n_boot: int = 1000
    alpha: float = 0.05
    relevance: float = 0.1
    min_share: float = 0.25
    seed: int = 0
    calibration: str = "linearized"
    confirm: int | None = 3
    split: str = "tail"
    burn_in: float = 0.0
    max_effects: int = 2
    workers: int = 1
    heldout_offset: str = "auto"

    def __post_init__(self) -> None:
        if not 0.1 <= self.train_fraction <= 0.9:
            raise ModelError(f"must be in [0.1, 0.9], got {self.train_fraction!r}", where="train_fraction")
        if self.blocks < 3 or self.n_null < 1 or self.n_boot < 10:
            raise ModelError("need blocks >= 3, n_null >= 1 and n_boot >= 10", where="diagnose_effects")
        if self.calibration not in ("linearized", "refit"):
            raise ModelError(f"must be 'linearized' or 'refit', got {self.calibration!r}", where="calibration")
        if self.confirm is not None and self.confirm < 1:
            raise ModelError(f"must be None or >= 1, got {self.confirm!r}", where="confirm")
        if self.max_effects < 1:
            raise ModelError(f"must be >= 1, got {self.max_effects!r}", where="max_effects")
        if self.heldout_offset not in ("auto", "carry", "fit"):
            raise ModelError(f"must be 'auto', 'carry' or 'fit', got {self.heldout_offset!r}", where="heldout_offset")
        if self.split not in ("tail", "interleaved"):
            raise ModelError(f"must be 'tail' or 'interleaved', got {self.split!r}", where="split")
        if not (np.isfinite(self.burn_in) and self.burn_in >= 0.0):
            raise ModelError(f"must be a number of seconds >= 0, got {self.burn_in!r}", where="burn_in")

    def to_dict(self) -> dict[str, Any]:
        """The options as plain values (candidates by label).

        Examples
        --------
        >>> DiagnoseOptions(candidates=("delay",)).to_dict()["candidates"]
        ['delay']
        """
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["candidates"] = [c if isinstance(c, str) else c.label for c in self.candidates]
        return out


def diagnose_effects(plant: Plant, record: Record, validate: Record | Sequence[Record] | None = None,
                     options: DiagnoseOptions | None = None, progress: dict[str, Any] | None = None) -> EffectDiagnosis:
    """Attribute the gap between ``plant`` and ``record`` to one effect, and measure its shrinkage.

    Parameters
    ----------
    Parameters
    ----------
    plant : Plant
        The nominal model (exact delay), driven by the record's input.
    record : Record
        Measured command and output, starting at rest.
    validate : Record or sequence of Record, optional
        Held-out record; without it the record is split (see the module text). Several records
        (runs of the same plant): each is simulated from rest at its own first input (joined by
        settling bridges, :mod:`synth.gap.attribution.stitch`), keeps its own held-out offset where offsets are
        fitted, and is cut into its own ``blocks`` segments, resampled within the run (stratified).
    options : DiagnoseOptions, optional
        Candidates, split, bootstrap and acceptance settings (default: :class:`DiagnoseOptions`).
    progress : dict, optional
        Filled as the fits go: ``"total"`` steps (the re-fit, the calibration, each candidate's screen or
        fit, each joint fit, the further effects), ``"done"`` and ``"step"`` (the last one finished), for
        a progress bar.

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
    >>> progress = {}
    >>> dg = diagnose_effects(Plant.from_string("2.1/(0.2*s+1)"), record_from_arrays(t, u, y),
    ...                       options=DiagnoseOptions(candidates=("delay",), n_null=5), progress=progress)
    >>> dg.verdict["effects"], round(dg.effects[0].parameters["delay"], 3), dg.effects[0].shrinkage > 0.9
    (['delay'], 0.05, True)
    >>> progress["done"] == progress["total"], progress["step"]
    (True, 'verdict')
    """
    options = DiagnoseOptions() if options is None else options
    (train_fraction, blocks, n_null, n_boot, alpha, relevance, min_share, seed, calibration, confirm, split, burn_in,
     max_effects, workers, heldout_offset) = (
        options.train_fraction, options.blocks, options.n_null, options.n_boot, options.alpha, options.relevance,
        options.min_share, options.seed, options.calibration, options.confirm, options.split, options.burn_in,
        options.max_effects, options.workers, options.heldout_offset)
    effects = [make_effect(c) for c in options.candidates]
    labels = [e.label for e in effects]
    if len(set(labels)) != len(labels):
        raise ModelError(f"repeated candidates in {labels}", where="candidates")
    if progress is not None:
        progress.update(done=0, step="start",
                        total=3 + len(effects) + (0 if confirm is None else min(confirm, len(effects))))
    rng = np.random.default_rng(seed)
    sp = split_heldout(plant, record, validate, split, train_fraction, blocks, burn_in)
    fit_offset = heldout_offset == "fit" or (heldout_offset == "auto" and sp.validation)
    t_tr, u_tr, y_tr = sp.train.t, sp.train.u, sp.train.y
    t_ev, u_ev, y_ev = sp.evaluated.t, sp.evaluated.u, sp.evaluated.y
    held, train_mask, groups, n_held = sp.held, sp.train_mask, sp.groups, sp.n_held
    if groups is None:
        ids = block_ids(n_held, blocks)
        draws = rng.integers(0, blocks, size=(n_boot, blocks))
        n_blocks = blocks
    else:  # each run its own segments, resampled within the run
        ids = np.concatenate([block_ids(int(np.sum(groups == r)), blocks) + r * blocks for r in range(sp.runs)])
        draws = np.concatenate([rng.integers(0, blocks, size=(n_boot, blocks)) + r * blocks
                                for r in range(sp.runs)], axis=1)
        n_blocks = blocks * sp.runs
    counts = np.bincount(ids, minlength=n_blocks).astype(float)
    boot_n = counts[draws].sum(axis=1)

    def sums(yhat: np.ndarray) -> np.ndarray:
        e = y_ev[held] - yhat[held]
        return _block_sums(demean(e, groups) ** 2 if fit_offset else e**2, ids, n_blocks)

    def shifted(yhat: np.ndarray | None) -> np.ndarray | None:
        """A prediction with its held-out offset re-estimated (as judged), for the figures."""
        if yhat is None or not fit_offset:
            return yhat
        out = yhat.copy()
        e = (y_ev - yhat)[held]
        out[held] += e - demean(e, groups)
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
    advance(progress, "re-fit")
    y_ref = refit.predict(t_ev, u_ev)
    s_nom, s_ref = sums(y_nom), sums(y_ref)
    j_nom, j_ref = float(s_nom.sum() / n_held), float(s_ref.sum() / n_held)
    # every settled sample of the evaluated record (same white noise) but those resting on a clip (they hold none)
    sigma = _moving_noise((y_ev - y_ref)[sp.settled], y_ev[sp.settled]) or noise_sigma((y_ev - y_ref)[sp.settled])
    floor = sigma**2
    pm_shrink = 1.0 - j_ref / j_nom if j_nom > 0 else 0.0
    pm_ci = ratio_ci(s_ref, s_nom)
    gap_present = float(np.quantile(boot(s_nom) / floor - 1.0, 0.025)) > relevance
    gap_after_refit = float(np.quantile(boot(s_ref) / floor - 1.0, 0.025)) > relevance

    # calibration: parametric bootstrap of the re-fit
    if calibration == "linearized":
        null = linearized_null(refit, t_tr, u_tr, t_ev, u_ev, held, not sp.validation, sigma, n_null, rng,
                                train_mask, fit_offset, groups)
    else:
        null = refit_null(refit, t_tr, u_tr, t_ev, u_ev, held, not sp.validation, sigma, n_null, rng, train_mask,
                           fit_offset, groups)
    threshold = float(np.quantile(null, 1.0 - alpha, method="higher"))
    advance(progress, "calibration")

    fits = candidate_fits(plant, effects, refit, sp.train, sp.evaluated, confirm, train_mask, workers, progress)
    # the floor from the re-fit's residual holds whatever that model misses at high frequency (a resonance at half
    # the Nyquist frequency put it at 3.5 times the noise, and "no gap"): each model's residual holds the noise and
    # its own error, so the least of them is the floor
    sigmas = [_moving_noise((y_ev - yhat)[sp.settled], y_ev[sp.settled]) for _, fit, _, yhat in fits
              if isinstance(fit, AugmentedFit)]
    sigmas = [x for x in sigmas if x > 0.0]
    if sigmas and min(sigmas) < sigma:
        sigma = min(sigmas)
        floor = sigma**2
        gap_present = float(np.quantile(boot(s_nom) / floor - 1.0, 0.025)) > relevance
        gap_after_refit = float(np.quantile(boot(s_ref) / floor - 1.0, 0.025)) > relevance

    # the form a joint fit kept (a dead zone's center held at rest or fitted) is what its parameters count
    by_label = {eff.label: (fit.effect if isinstance(fit, AugmentedFit) and fit.effect is not None else eff, fit)
                for eff, fit, _, _ in fits}
    results: list[tuple[EffectResult, np.ndarray, np.ndarray]] = []
    for eff, fit, _, yhat in fits:
        s = sums(yhat)
        j = float(s.sum() / n_held)
        shrink = 1.0 - j / j_ref if j_ref > 0 else 0.0
        ci = ratio_ci(s, s_ref)
        share = share_of_excess(j_nom, j, floor)  # at most 1: a model below the floor's estimate removes it all
        share_ref = share_of_excess(j_ref, j, floor)
        significant = bool(gap_present and ci[0] > threshold)
        joint = isinstance(fit, AugmentedFit)
        params = {k: float(fit.params[k]) for k in eff.parameter_names}
        unphysical = wrong_sign(eff, params, sp.train.t, sp.train.u, plant)
        # and the model with the effect must do better than the nominal one too: after a re-fit that made the
        # held-out error worse, beating the re-fit alone is not explaining the gap (share of it <= 0)
        relevant = bool(significant and share_ref >= min_share and joint and not unphysical and j < j_nom)
        p_ci = fit.parameter_ci if joint else {}
        nominal = dict(fit.nominal) if joint else screened_coefficients(fit.plant)
        res = EffectResult(eff.label, params, p_ci, shrink, ci, significant, float(share), relevant, j, nominal,
                           "joint" if joint else "screened", unphysical)
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
        counts = [free_parameters(by_label[r.effect][0], r.parameters) for r, _, _ in relevant]
        lead, parsimony = parsimonious_lead([(r.effect, s) for r, _, s in relevant], counts, ratio_ci, threshold)
        best, y_best, s_best = relevant[lead]
        verdict_effects = [best.effect]
        status = "effect"
        group = [best.effect]
        for res, yhat, s in results:
            if res.effect == best.effect or not res.significant or res.unphysical:
                continue
            d_lo, d_hi = diff_ci(s, s_best)
            same_j = d_lo <= 0.0 <= d_hi
            gap_ab = (yhat - y_best)[held]
            rms_diff = float(np.sqrt(np.mean((demean(gap_ab, groups) if fit_offset else gap_ab) ** 2)))
            # outputs a tenth of the noise apart: any difference in J is the noise's, whatever the bootstrap says;
            # outputs apart by more with the same J: the record prefers neither (both can miss it alike)
            same_j = same_j or rms_diff < 0.1 * sigma
            if same_j:
                group.append(res.effect)
                experiments.append(separating_experiment(best.effect, res.effect, t_ev[held], y_best[held], yhat[held]))
        if len(group) > 1:
            indist.append(group)
        results = [(r if r.effect == best.effect else replace(r, accepted=False), y, s) for r, y, s in results]
        chain = ForwardSelection(plant, sp.train, sp.evaluated, weights, train_mask, sums, ratio_ci, threshold,
                                 min_share, floor, n_held, workers)
        eff_best, fit_best = by_label[best.effect]
        tried = {best.effect, *group}
        while len(verdict_effects) < max_effects:
            if float(np.quantile(boot(s_best) / floor - 1.0, 0.025)) <= relevance:
                break  # the accepted model is within the noise: a further effect would fit the noise (a resonance
                # on a rate limit that had reached the noise, a black-box helper)
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
    if progress is not None:
        progress.update(done=progress.get("total", 0), step="verdict")
    verdict = {"effects": verdict_effects, "indistinguishable": indist, "experiments": experiments,
               "status": status, "headline": headline(status, verdict_effects, indist, results, pm_shrink, j_nom, floor),
               "parsimony": parsimony}
    n_train = int(t_tr.size if train_mask is None else train_mask.sum())
    split = {"train_samples": n_train, "heldout_samples": n_held, "blocks": blocks, "n_null": n_null,
             "n_boot": n_boot, "alpha": alpha, "validation_record": sp.validation, "seed": seed,
             "calibration": calibration, "confirm": confirm, "split": sp.mode,
             "burn_in": burn_in, "heldout_offset": "fit" if fit_offset else "carry",
             "validation_runs": sp.runs,
             "joint_fits": [r.effect for r, _, _ in results if r.fit == "joint"]}
    return EffectDiagnosis([r for r, _, _ in results], verdict, floor, j_nom, j_ref, pm_shrink, pm_ci, threshold,
                           refit, split, t_ev, y_ev, shifted(y_nom), shifted(y_ref), shifted(y_best), held, segments)


def _moving_noise(e: np.ndarray, y: np.ndarray) -> float:
    """:func:`noise_sigma` of a residual ``e`` over the samples where the measured output ``y`` does not rest on its
    largest or smallest value: resting on a clip it holds no noise, and the residual's second differences there are
    the model's smooth curve (a record clipped over half its samples had a floor of 3e-9 for a noise variance of
    2.5e-5; 0 where fewer than 5 samples are left). A quantized output's equal neighbours inside its range stay in."""
    y = np.asarray(y, float)
    edge = (y == np.max(y)) | (y == np.min(y))
    moving = np.flatnonzero(~(edge[:-2] & edge[1:-1] & edge[2:]))
    return float(noise_sigma(e, moving)) if moving.size >= 5 else 0.0
