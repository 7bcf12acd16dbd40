"""The verdict's types: one candidate judged on held-out data, the whole diagnosis, and its wording.

:class:`EffectResult` (one candidate), :class:`HeldoutSegments` (every model's held-out cost by
bootstrap segment, for pooling), :class:`EffectDiagnosis` (what
:func:`synth.gap.attribution.heldout.diagnose_effects` returns), the experiments that separate two
effects the data could not tell apart (:data:`SEPARATING_EXPERIMENTS`, :func:`separating_experiment`)
and the one-line :func:`headline`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.gap.attribution.refit import AugmentedFit

__all__ = ["CONCENTRATED_RATIO", "SEPARATING_EXPERIMENTS", "EffectDiagnosis", "EffectResult", "HeldoutSegments",
           "aux_explained", "headline", "not_carried", "separating_experiment"]

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


@dataclass(frozen=True)
class EffectResult:
    """One candidate effect judged on held-out data.

    Attributes
    ----------
    effect : str
    parameters : dict
        Fitted effect parameters.
    parameter_ci : dict
        Their approximate 95 % intervals (see :mod:`synth.gap.attribution.refit`).
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
        (denominator fixed, see :mod:`synth.gap.attribution.screen`; never accepted).
    unphysical : str
        Why the fitted parameters leave the effect's physical range for this record
        (:func:`synth.gap.attribution.physical.wrong_sign`); such a candidate is never accepted. Empty: inside it.
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
    unphysical: str = ""

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
                "j_heldout": self.j_heldout, "nominal": dict(self.nominal), "fit": self.fit,
                **({"unphysical": self.unphysical} if self.unphysical else {})}


@dataclass(frozen=True, eq=False)
class HeldoutSegments:
    """The held-out cost of every model by bootstrap segment (what :mod:`synth.gap.attribution.roundrobin` pools).

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
        fewer parameters leads over the lowest-``J`` one, see :func:`parsimonious_lead`).
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
        >>> from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
        >>> from synth.ident.simulate import simulate_plant
        >>> from synth.plant import Plant
        >>> t = np.arange(0, 8, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
        >>> G = Plant.from_string("2/(0.2*s+1)")
        >>> y = simulate_plant(G, t, u) + 0.01 * np.random.default_rng(1).normal(size=t.size)
        >>> d = diagnose_effects(G, record_from_arrays(t, u, y),
        ...                      options=DiagnoseOptions(candidates=("delay",), n_null=5)).to_dict()
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


def separating_experiment(a: str, b: str, t: np.ndarray, ya: np.ndarray, yb: np.ndarray) -> str:
    """The experiment that would separate effects ``a`` and ``b`` (their held-out outputs ``ya``, ``yb`` at ``t``).

    A known pair gets its entry of :data:`SEPARATING_EXPERIMENTS`; any other pair, the regime where the
    two outputs differ most.

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0])
    >>> separating_experiment("delay", "lag", t, t, t).split(":")[0]
    'delay vs lag'
    >>> separating_experiment("backlash", "drift", t, np.zeros(3), np.array([0.0, 0.5, 0.1]))
    'backlash vs drift: excite the regime where their outputs differ most (held-out t = 1 s, difference 0.5)'
    """
    key = frozenset({a, b})
    if key in SEPARATING_EXPERIMENTS:
        return f"{a} vs {b}: {SEPARATING_EXPERIMENTS[key]}"
    k = int(np.argmax(np.abs(ya - yb)))
    return (f"{a} vs {b}: excite the regime where their outputs differ most (held-out t = {t[k]:.3g} s, "
            f"difference {abs(ya[k] - yb[k]):.3g})")


CONCENTRATED_RATIO = 1.5
"""A held-out error at least this many times the noise floor is not "within the noise floor" even where its interval
over segments reaches it (a residual in one short stretch: J/sigma^2 = 37.9 had been called within it)."""


def headline(status: str, effects: list[str], indist: list[list[str]], results: list[Any], pm: float,
             j_nom: float, floor: float) -> str:
    """The verdict in one line.

    Parameters
    ----------
    status : {"none", "effect", "parameter_mismatch", "unexplained"}
    effects : list of str
        The verdict's effects.
    indist : list of list of str
        Indistinguishable groups (the leader first).
    results : list of (EffectResult, numpy.ndarray, numpy.ndarray)
        Every candidate's result, held-out output and segment sums.
    pm : float
        Held-out shrinkage of the re-fit against the nominal model.
    j_nom, floor : float
        The nominal model's held-out ``J`` and the noise floor.

    Returns
    -------
    str

    Examples
    --------
    >>> headline("none", [], [], [], 0.0, 1.05, 1.0)
    "no gap: the nominal model's held-out error is within the noise floor (J/sigma^2 = 1.05)"
    >>> headline("none", [], [], [], 0.0, 37.9, 1.0).split(",")[0]
    "no consistent gap: the nominal model's held-out error is 37.90 times the noise floor"
    """
    if status == "none" and j_nom / floor >= CONCENTRATED_RATIO:
        return (f"no consistent gap: the nominal model's held-out error is {j_nom / floor:.2f} times the noise floor, "
                "but its 95 % interval over the held-out segments reaches the floor: the error comes from a few "
                "segments (see where in the residual map)")
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


def not_carried(diagnosis: EffectDiagnosis, confirm: int | None, min_share: float = 0.25,
                top: int = 3) -> list[dict[str, Any]]:
    """Why each promising candidate is not in the verdict: the significant ones and the ``top`` by shrinkage.

    A candidate the screen ranked below the ``confirm`` best (by screened training error) is never
    re-fitted jointly, and a screened fit cannot be the verdict; a joint fit may fall short of the
    calibrated threshold, of ``min_share`` of the re-fit's excess over noise, leave the effect's physical
    range, or be grouped with or displaced by the leader.

    Parameters
    ----------
    diagnosis : EffectDiagnosis
    confirm : int or None
        Screened candidates re-fitted jointly (:class:`synth.gap.attribution.heldout.DiagnoseOptions`).
    min_share : float
        Share of the re-fit's excess over noise an accepted effect must remove.
    top : int
        Candidates by held-out shrinkage always explained.

    Returns
    -------
    list of dict
        ``{"effect", "shrinkage", "shrinkage_ci", "fit", "reason"}``, best shrinkage first.

    Examples
    --------
    >>> from types import SimpleNamespace as S
    >>> r = EffectResult("deadzone", {}, {}, 0.52, (0.36, 0.67), True, 0.5, False, 1.0, {}, "screened")
    >>> dg = S(effects=[r], verdict={"effects": ["parameter_mismatch"], "indistinguishable": []},
    ...        split={"joint_fits": ["lag", "delay", "drift"]}, threshold=0.05, j_refit=2.0, noise_floor=0.5)
    >>> not_carried(dg, 3)[0]["reason"][:60]  # the only candidate: it was sent to the joint fit
    'screened, but its joint re-fit with the nominal coefficients'
    >>> not_carried(dg, None)[0]["reason"][:50]
    'screened only: not among the None best by screened'
    """
    from synth.gap.attribution.parsimony import share_of_excess

    verdict = diagnosis.verdict
    named = set(verdict.get("effects", []))
    grouped = {e for g in verdict.get("indistinguishable", []) for e in g[1:]}
    joint = list(diagnosis.split.get("joint_fits", []))
    ranked = sorted(diagnosis.effects, key=lambda r: -r.shrinkage)
    screened_only = sum(1 for r in diagnosis.effects if r.fit != "joint")
    n_joint = sum(1 for r in diagnosis.effects if r.fit == "joint" and "+" not in r.effect)
    out = []
    for i, r in enumerate(ranked):
        label = r.effect.split("+")[-1]
        if label in named or r.effect in named or not (r.significant or i < top) or r.shrinkage <= 0:
            continue
        lo, hi = r.shrinkage_ci
        if r.fit != "joint" and confirm is not None and screened_only + n_joint <= confirm:
            reason = ("screened, but its joint re-fit with the nominal coefficients failed (e.g. the least squares "
                      "lost the plant's gain: the signal is collinear with the command); a screened fit (denominator "
                      "held) cannot be the verdict")
        elif r.fit != "joint":
            reason = (f"screened only: not among the {confirm} best by screened training error, which were "
                      f"re-fitted jointly ({', '.join(joint) or 'none'}), or its joint re-fit failed; a screened fit "
                      "(denominator held) cannot be the verdict: name it alone with --candidates to fit it jointly")
        elif r.unphysical:
            reason = (f"fitted jointly, but not a physical {label.replace('_', ' ')}: {r.unphysical} (the data "
                      "fit better with it, but through a mechanism no such effect has)")
        elif not r.significant:
            reason = (f"fitted jointly; its held-out shrinkage interval [{lo:.2f}, {hi:.2f}] does not clear the "
                      f"calibrated threshold {diagnosis.threshold:.3f}")
        elif r.effect in grouped:
            reason = "fitted jointly and significant, but indistinguishable from the leader (see the group)"
        else:
            share = share_of_excess(diagnosis.j_refit, r.j_heldout, diagnosis.noise_floor)
            if share < min_share:
                reason = (f"fitted jointly and significant, but removes only {100 * share:.0f} % of the re-fit's "
                          f"excess over noise (needs {100 * min_share:.0f} %)")
            elif "+" not in r.effect and r.j_heldout >= diagnosis.j_nominal:
                reason = (f"fitted jointly and significant against the re-fit, but its held-out error is no lower "
                          f"than the nominal model's ({r.j_heldout:.4g} >= {diagnosis.j_nominal:.4g}): the re-fit "
                          "made the held-out error worse, and beating it explains nothing")
            elif "+" in r.effect:
                reason = "tried on top of the first effect; not accepted against the model before it"
            else:
                reason = "fitted jointly and accepted, but a simpler or better effect leads (see parsimony)"
        out.append({"effect": r.effect, "shrinkage": r.shrinkage, "shrinkage_ci": [float(lo), float(hi)],
                    "fit": r.fit, "reason": reason})
    return out


def aux_explained(diagnosis: EffectDiagnosis, channels: dict[str, str]) -> list[dict[str, Any]]:
    """How much each measured aux channel explained: its best effect's held-out shrinkage and share of the gap.

    Parameters
    ----------
    diagnosis : EffectDiagnosis
    channels : dict
        Effect label -> the aux channel that drives it.

    Returns
    -------
    list of dict
        ``{"channel", "effect", "shrinkage", "shrinkage_ci", "share_of_gap", "accepted"}`` per channel,
        the best-explaining first.

    Examples
    --------
    >>> from types import SimpleNamespace as S
    >>> r = EffectResult("measured_sag(V)", {"sag": 1.0}, {}, 0.8, (0.7, 0.9), True, 0.9, True, 1.0, {})
    >>> aux_explained(S(effects=[r]), {"measured_sag(V)": "V"})[0]["channel"]
    'V'
    """
    best: dict[str, EffectResult] = {}
    for r in diagnosis.effects:
        ch = channels.get(r.effect.split("+")[-1])
        if ch is not None and (ch not in best or r.shrinkage > best[ch].shrinkage):
            best[ch] = r
    rows = [{"channel": ch, "effect": r.effect, "shrinkage": r.shrinkage,
             "shrinkage_ci": [float(x) for x in r.shrinkage_ci], "share_of_gap": r.share_of_gap,
             "accepted": r.accepted} for ch, r in best.items()]
    return sorted(rows, key=lambda d: -d["shrinkage"])
