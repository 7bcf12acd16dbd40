"""One diagnosis from several runs of one plant: each run trains, the others are held out, the evidence pooled.

A record with a single transient cannot confirm an effect that only shows in
transients: held out, its one step falls in one bootstrap segment, and the
interval of the shrinkage reaches down to "no step at all". Several runs of the
same plant (a lab's open-loop step and its closed-loop steps) can. Procedure
(:func:`diagnose_runs`):

1. **Folds.** For each run, :func:`synth.gap.attribution.heldout.diagnose_effects` fits the
   re-fit and every candidate on that run and judges them on all the other runs
   (each simulated from rest at its own first input, with its own held-out offset,
   cut into its own segments).
2. **Pooling.** Each model's held-out cost is the sum over the folds. The interval
   resamples the segments of each run with replacement; a run held out in several
   folds is drawn the same way in all of them (its segments are the unit, whichever
   model predicted them), so the folds' shared data are not counted as independent.
3. **Verdict** as for one record (:mod:`synth.gap.attribution.heldout`): significant when the
   lower end of the pooled interval exceeds the largest of the folds' calibrated
   thresholds (conservative), relevant when it also removes ``min_share`` of the
   re-fit's pooled excess over the noise floor and it was fitted jointly in every
   fold; the simplest relevant candidate not beaten significantly leads; candidates
   whose pooled ``J`` does not differ from the leader's, or whose outputs differ by
   less than a tenth of the noise, are indistinguishable. One effect at most (no forward selection).
4. **Parameters** are reported per training run: their spread across runs is how
   well the data pin the effect down.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from synth.data.record import Record
from synth.errors import ModelError
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.attribution.parsimony import fitted_form, free_parameters, parsimonious_lead, share_of_excess
from synth.gap.attribution.verdict import EffectDiagnosis, separating_experiment
from synth.gap.effects.registry import DEFAULT_CANDIDATES, make_effect
from synth.plant import Plant

__all__ = ["PooledEffect", "RunsDiagnosis", "diagnose_runs"]


@dataclass(frozen=True)
class PooledEffect:
    """One candidate judged on every run held out.

    Attributes
    ----------
    effect : str
    parameters : list of dict
        Fitted effect parameters, one dict per training run (``None`` where its fit was only screened).
    shrinkage : float
        ``1 - J_with / J_refit`` pooled over the folds.
    shrinkage_ci : tuple of float
        95 % interval (segments resampled within each run).
    significant, accepted : bool
    share_of_gap : float
        Part of the re-fit's pooled held-out excess over the noise floor removed.
    j_heldout : float
        Pooled held-out mean squared error (output units squared).
    unphysical : str
        Why a run's fit is not the effect it names (:func:`synth.gap.attribution.physical.wrong_sign`; never
        accepted, nor counted as indistinguishable from the verdict). Empty: physical in every run.
    """

    effect: str
    parameters: list[dict[str, float] | None]
    shrinkage: float
    shrinkage_ci: tuple[float, float]
    significant: bool
    share_of_gap: float
    accepted: bool
    j_heldout: float
    unphysical: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON entry of ``"effects"``.

        Examples
        --------
        >>> PooledEffect("delay", [{"delay": 0.04}], 0.3, (0.1, 0.5), True, 0.4, True, 9.0).to_dict()["shrinkage_ci"]
        [0.1, 0.5]
        """
        return {"effect": self.effect, "parameters_by_run": [None if p is None else dict(p) for p in self.parameters],
                "shrinkage": self.shrinkage, "shrinkage_ci": [float(x) for x in self.shrinkage_ci],
                "significant": self.significant, "share_of_gap": self.share_of_gap, "accepted": self.accepted,
                "j_heldout": self.j_heldout, **({"unphysical": self.unphysical} if self.unphysical else {})}


@dataclass(frozen=True, eq=False)
class RunsDiagnosis:
    """The pooled verdict of a round robin over runs, and each fold's own diagnosis.

    Attributes
    ----------
    runs : list of str
        Names of the runs, in the order given.
    effects : list of PooledEffect
        Every candidate fitted in all folds, largest pooled shrinkage first.
    verdict : dict
        ``effects``, ``indistinguishable``, ``experiments``, ``status``, ``headline``, ``parsimony``
        (as :class:`synth.gap.attribution.verdict.EffectDiagnosis`).
    noise_floor, j_nominal, j_refit, threshold : float
        Pooled noise floor and held-out errors (output units squared); the threshold is the largest
        of the folds' calibrated thresholds.
    refit_shrinkage : float
    refit_shrinkage_ci : tuple of float
    folds : list of EffectDiagnosis
        Fold ``i``: trained on run ``i``, held out on the others.
    """

    runs: list[str]
    effects: list[PooledEffect]
    verdict: dict[str, Any]
    noise_floor: float
    j_nominal: float
    j_refit: float
    refit_shrinkage: float
    refit_shrinkage_ci: tuple[float, float]
    threshold: float
    folds: list[EffectDiagnosis] = field(repr=False)

    @property
    def summary(self) -> str:
        """The pooled verdict in plain sentences, with the effect's parameters on each training run.

        Examples
        --------
        >>> RunsDiagnosis(["a", "b"], [], {"effects": [], "status": "none"}, 1.0, 1.0, 1.0, 0.0, (0.0, 0.0), 0.0,
        ...               []).summary[:39]
        'No gap beyond the measurement noise in '
        """
        v, n = self.verdict, len(self.runs)
        where = f"{n} runs, each fitted once and judged on the other {n - 1}"
        if v["status"] == "none":
            return f"No gap beyond the measurement noise in {where}."
        if v["status"] != "effect":
            text = f"No candidate effect is confirmed over {where}"
            if v["effects"] == ["parameter_mismatch"]:
                text += f"; re-fitting the nominal coefficients shrinks the gap by {self.refit_shrinkage:.2f}"
            return text + "."
        best = next(e for e in self.effects if e.effect == v["effects"][0])
        lo, hi = best.shrinkage_ci
        per_run = "; ".join(
            f"{name}: " + (", ".join(f"{k} = {x:.4g}" for k, x in p.items()) if p is not None else "screened only")
            for name, p in zip(self.runs, best.parameters))
        text = (f"Over {where}, {best.effect.replace('_', ' ')} shrinks the held-out error by {best.shrinkage:.2f} "
                f"[{lo:.2f}, {hi:.2f}] (threshold {self.threshold:.3g}). Fitted on each run: {per_run}.")
        others = [e for e in self.effects if e.significant and e.effect != best.effect and not e.unphysical]
        if others:
            text += " Also significant: " + ", ".join(
                f"{e.effect} {e.shrinkage:.2f} [{e.shrinkage_ci[0]:.2f}, {e.shrinkage_ci[1]:.2f}]" for e in others) + "."
        if v["indistinguishable"]:
            text += " The data cannot tell it from " + ", ".join(v["indistinguishable"][0][1:]) + "."
        return text

    def to_dict(self) -> dict[str, Any]:
        """JSON: the pooled verdict and effects, and each fold's diagnosis.

        Examples
        --------
        >>> RunsDiagnosis(["a", "b"], [], {"effects": [], "status": "none"}, 1.0, 1.0, 1.0, 0.0, (0.0, 0.0), 0.0,
        ...               []).to_dict()["runs"]
        ['a', 'b']
        """
        return {"runs": list(self.runs), "verdict": dict(self.verdict), "summary": self.summary,
                "effects": [e.to_dict() for e in self.effects], "noise_floor": self.noise_floor,
                "j_nominal": self.j_nominal, "j_refit": self.j_refit, "threshold": self.threshold,
                "parameter_mismatch": {"shrinkage": self.refit_shrinkage,
                                       "shrinkage_ci": [float(x) for x in self.refit_shrinkage_ci]},
                "folds": [{"train": self.runs[i], "heldout": [r for j, r in enumerate(self.runs) if j != i],
                           **f.to_dict()} for i, f in enumerate(self.folds)]}


def diagnose_runs(plant: Plant, runs: Sequence[Record], candidates: Sequence[str] = DEFAULT_CANDIDATES,
                  names: Sequence[str] | None = None, *, blocks: int = 10, n_null: int = 199, n_boot: int = 1000,
                  alpha: float = 0.05, relevance: float = 0.1, min_share: float = 0.25, seed: int = 0,
                  confirm: int | None = 3, burn_in: float = 0.0, workers: int = 1) -> RunsDiagnosis:
    """Round robin over runs of one plant: each trains once, the others are held out; the verdict pools them.

    Parameters
    ----------
    plant : Plant
        The nominal model (stable: each run is simulated from rest).
    runs : sequence of Record
        At least two runs with the same sample time and units, each starting at rest.
    candidates : sequence of str
        Effects to try.
    names : sequence of str, optional
        Run names for the report (default ``run 1``, ``run 2``, ...).
    blocks, n_null, n_boot, alpha, relevance, min_share, seed, confirm, burn_in, workers
        As :func:`synth.gap.attribution.heldout.diagnose_effects` (``blocks``: segments per held-out run).

    Returns
    -------
    RunsDiagnosis

    Raises
    ------
    ModelError
        Fewer than two runs, or names that do not match the runs.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> G, rng = Plant.from_string("2/(0.2*s+1)"), np.random.default_rng(0)
    >>> def run(level):
    ...     t = np.arange(0, 4, 0.01); u = np.where(t >= 1, level, 0.0)
    ...     y = simulate_plant(G.with_delay(0.05), t, u) + 0.01 * rng.normal(size=t.size)
    ...     return record_from_arrays(t, u, y)
    >>> d = diagnose_runs(G, [run(1.0), run(0.5), run(1.5)], ["delay"], n_null=9)
    >>> d.verdict["effects"], [round(p["delay"], 2) for p in d.effects[0].parameters]
    (['delay'], [0.05, 0.05, 0.05])
    """
    runs = list(runs)
    if len(runs) < 2:
        raise ModelError(f"a round robin needs at least two runs, got {len(runs)}", where="runs")
    names = [f"run {i + 1}" for i in range(len(runs))] if names is None else list(names)
    if len(names) != len(runs):
        raise ModelError(f"{len(names)} names for {len(runs)} runs", where="names")
    options = DiagnoseOptions(candidates=tuple(candidates), blocks=blocks, n_null=n_null, n_boot=n_boot, alpha=alpha,
                              relevance=relevance, min_share=min_share, seed=seed, confirm=confirm, burn_in=burn_in,
                              max_effects=1, workers=workers, heldout_offset="fit")
    folds = [diagnose_effects(plant, runs[i], [r for j, r in enumerate(runs) if j != i], replace(options, seed=seed + i))
             for i in range(len(runs))]
    return _pool(folds, names, blocks, n_boot, alpha, relevance, min_share, seed)


def _pool(folds: list[EffectDiagnosis], names: list[str], blocks: int, n_boot: int, alpha: float, relevance: float,
          min_share: float, seed: int) -> RunsDiagnosis:
    """The pooled verdict of the folds (see the module text)."""
    rng = np.random.default_rng(seed)
    n_runs = len(names)
    draws = {g: rng.integers(0, blocks, size=(n_boot, blocks)) for g in range(n_runs)}
    cols, offset = [], 0
    for i, fold in enumerate(folds):
        others = [j for j in range(n_runs) if j != i]
        for local, g in enumerate(others):  # the fold's segments of held-out run g: the same draws in every fold
            cols.append(offset + local * blocks + draws[g])
        offset += fold.segments.counts.size
    index = np.concatenate(cols, axis=1)
    labels = [k for k in folds[0].segments.sums if all(k in f.segments.sums for f in folds)]
    sums = {k: np.concatenate([f.segments.sums[k] for f in folds]) for k in labels}
    counts = np.concatenate([f.segments.counts for f in folds])
    n_held = float(counts.sum())
    boot_n = counts[index].sum(axis=1)

    def boot(s: np.ndarray) -> np.ndarray:
        return s[index].sum(axis=1) / boot_n

    def ratio_ci(num: np.ndarray, den: np.ndarray) -> tuple[float, float]:
        r = 1.0 - boot(num) / boot(den)
        return float(np.quantile(r, 0.025)), float(np.quantile(r, 0.975))

    floor = float(sum(f.noise_floor * f.segments.counts.sum() for f in folds) / n_held)
    sigma = float(np.sqrt(floor))
    threshold = max(f.threshold for f in folds)
    j_nom, j_ref = float(sums["nominal"].sum() / n_held), float(sums["refit"].sum() / n_held)
    pm_ci = ratio_ci(sums["refit"], sums["nominal"])
    gap_present = float(np.quantile(boot(sums["nominal"]) / floor - 1.0, 0.025)) > relevance
    gap_after_refit = float(np.quantile(boot(sums["refit"]) / floor - 1.0, 0.025)) > relevance
    by_fold = [{e.effect: e for e in f.effects} for f in folds]
    pooled: list[PooledEffect] = []
    for label in labels:
        if label in ("nominal", "refit"):
            continue
        j = float(sums[label].sum() / n_held)
        ci = ratio_ci(sums[label], sums["refit"])
        significant = bool(gap_present and ci[0] > threshold)
        joint = all(b[label].fit == "joint" for b in by_fold)
        share = share_of_excess(j_ref, j, floor)
        params = [dict(b[label].parameters) if b[label].fit == "joint" else None for b in by_fold]
        unphysical = next((f"{name}: {b[label].unphysical}" for name, b in zip(names, by_fold) if b[label].unphysical),
                          "")  # a run's fit is not the effect it names
        pooled.append(PooledEffect(label, params, 1.0 - j / j_ref if j_ref > 0 else 0.0, ci, significant,
                                   float(share), bool(significant and joint and not unphysical and share >= min_share),
                                   j, unphysical))
    pooled.sort(key=lambda e: -e.shrinkage)
    relevant = [e for e in pooled if e.accepted]
    indist: list[list[str]] = []
    experiments: list[str] = []
    parsimony = None
    if not gap_present:
        effects, status = [], "none"
    elif relevant:
        # a nested effect's richer form (a dead zone's fitted center) when any run's fit kept it: the runs' intervals
        forms = [fitted_form(make_effect(e.effect), {k for b in by_fold for k in b[e.effect].parameter_ci})
                 for e in relevant]
        counts_p = [free_parameters(f, next(p for p in e.parameters if p is not None)) for f, e in zip(forms, relevant)]
        lead, parsimony = parsimonious_lead([(e.effect, sums[e.effect]) for e in relevant], counts_p, ratio_ci,
                                             threshold)
        best = relevant[lead]
        effects, status = [best.effect], "effect"
        group = [best.effect]
        y_best = np.concatenate([f.segments.predictions[best.effect] for f in folds])
        for e in pooled:
            if e.effect == best.effect or not e.significant or e.unphysical:
                continue
            d = (boot(sums[e.effect]) - boot(sums[best.effect])) / boot(sums["refit"])
            same_j = float(np.quantile(d, 0.025)) <= 0.0 <= float(np.quantile(d, 0.975))
            y_e = np.concatenate([f.segments.predictions[e.effect] for f in folds])
            rms = float(np.sqrt(np.mean((y_e - y_best) ** 2)))
            if same_j or rms < 0.1 * sigma:
                group.append(e.effect)
                experiments.append(separating_experiment(best.effect, e.effect, np.arange(y_best.size), y_best, y_e))
        if len(group) > 1:
            indist.append(group)
        pooled = [e if e.effect == best.effect else _unaccepted(e) for e in pooled]
    elif pm_ci[0] > 0.0:
        effects, status = ["parameter_mismatch"], ("unexplained" if gap_after_refit else "parameter_mismatch")
    else:
        effects, status = [], "unexplained"
    verdict = {"effects": effects, "indistinguishable": indist, "experiments": experiments, "status": status,
               "headline": _headline(status, effects, pooled, len(names), 1.0 - j_ref / j_nom if j_nom > 0 else 0.0),
               "parsimony": parsimony}
    return RunsDiagnosis(names, pooled, verdict, floor, j_nom, j_ref, 1.0 - j_ref / j_nom if j_nom > 0 else 0.0,
                         pm_ci, threshold, folds)


def _unaccepted(e: PooledEffect) -> PooledEffect:
    from dataclasses import replace

    return replace(e, accepted=False)


def _headline(status: str, effects: list[str], pooled: list[PooledEffect], n_runs: int, pm: float) -> str:
    where = f"held out on every other run of {n_runs}, each run trained once"
    if status == "effect":
        best = next(e for e in pooled if e.effect == effects[0])
        lo, hi = best.shrinkage_ci
        return f"{best.effect}: the gap shrinks by {best.shrinkage:.2f} [{lo:.2f}, {hi:.2f}] ({where})"
    if status == "none":
        return f"no gap beyond the noise floor ({where})"
    if effects == ["parameter_mismatch"]:
        return f"a re-fit of the nominal parameters shrinks the gap by {pm:.2f}; no effect is confirmed ({where})"
    return f"gap not explained by the candidate effects ({where})"
