"""A diagnosis's verdict in plain sentences: what to tell a person first (:attr:`synth.gap.diagnose.Diagnosis.summary`).

When re-fitting the nominal model's coefficients alone removes most of the gap and the model re-fitted with the
accepted effect still differs from the nominal one, the effect explains part of what the re-fit leaves, not the
whole gap: the sentence gives both shares and that model with its DC gain against the nominal one's (a DC motor with
its brake on, against the no-load model: the re-fit removes 99.97 % of the gap, at 0.61 times the gain, a slow
supply sag some of the rest). That change is a parameter mismatch, or the share of an effect the candidates miss
that the linear part takes (the X-4 rig's rate limit beside its saturation bends the re-fitted model to 1.18 times
the gain and a right-half-plane zero): the sentence names both readings. When the model re-fitted with the effect
is the nominal one again, the effect explains the gap (the re-fit alone had bent the model toward it).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from synth.data.record import Record
from synth.gap.attribution.nominal import plant_from_values
from synth.gap.attribution.verdict import CONCENTRATED_RATIO, EffectDiagnosis
from synth.plant import Plant

__all__ = ["CHANGED", "LEFT_OVER", "MOSTLY_REFIT", "format_parameter", "refit_share_of_gap", "refit_text", "response_change",
           "verdict_sentence"]

MOSTLY_REFIT = 0.5
"""When re-fitting the nominal coefficients alone removes at least this share of the gap above noise, and the model
re-fitted with the accepted effect still differs from the nominal one (:data:`CHANGED`), the summary gives the re-fit's
share and the effect's beyond it, and that model."""
LEFT_OVER = 4.0
"""A verdict's model whose held-out error is still above this many noise floors explains only part of the gap (an
integrating plant with an unknown start state: "drift removes 100 %" of a gap 446 % NRMSE, its held-out error 250
noise variances)."""


def refit_share_of_gap(refit_shrinkage: float, j_nominal: float, floor: float) -> float:
    """``(J_nominal - J_refit) / (J_nominal - sigma^2)``: the share of the nominal model's held-out excess over the
    noise floor that re-fitting its coefficients removes (0 without an excess).

    Examples
    --------
    >>> round(refit_share_of_gap(0.9, 100.0, 10.0), 4)   # J_refit = 10: all of the excess
    1.0
    """
    excess = j_nominal - floor
    return float(refit_shrinkage * j_nominal / excess) if excess > 0 else 0.0


CHANGED = 0.1
"""The relative change of the frequency response (:func:`response_change`) from which the model re-fitted with an
effect is a different model: a rate-limited record's re-fit alone removes 87 % of the gap by bending the linear model
toward the ramps, but re-fitted with the rate limit the model is the nominal one again (0.2 % off); with the brake on,
the DC motor's is 38 % off."""


def response_change(model: Plant, nominal: Plant) -> float:
    """The largest ``|G_model / G_nominal - 1|`` over 0.1 times the nominal's slowest pole or zero to 10 times its
    fastest (1 rad/s for a model without any), the delay left out.

    Examples
    --------
    >>> round(response_change(Plant.from_string("1.5/(s+1)"), Plant.from_string("2/(s+1)")), 3)
    0.25
    """
    roots = np.abs(np.r_[np.roots(nominal.num), np.roots(nominal.den)])
    roots = roots[roots > 0]
    lo, hi = (float(roots.min()), float(roots.max())) if roots.size else (1.0, 1.0)
    w = np.geomspace(0.1 * lo, 10.0 * hi, 200)
    s = 1j * w
    ratio = (np.polyval(model.num, s) / np.polyval(model.den, s)) / (np.polyval(nominal.num, s) / np.polyval(nominal.den, s))
    return float(np.max(np.abs(ratio - 1.0)))


def format_parameter(x: float) -> str:
    """A parameter as the effects' table writes it (an absent limit is ``inf`` or ``-inf``).

    Examples
    --------
    >>> format_parameter(0.123456), format_parameter(float("-inf"))
    ('0.1235', '-inf')
    """
    return f"{x:.4g}" if np.isfinite(x) else ("inf" if x > 0 else "-inf")


def refit_text(refit: Plant, nominal: Plant, record: Record) -> str:
    """The re-fitted nominal model and its DC gain against the nominal one's, in the record's units.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> rec = record_from_arrays(np.arange(3.0), np.arange(3.0), np.arange(3.0))
    >>> refit_text(Plant.from_string("1.5/(s+1)"), Plant.from_string("2/(s+1)"), rec)
    're-fitted 1.5/(s+1), DC gain 1.5 against 2 nominal (0.75 x)'
    """
    unit = "/".join(u for u in (record.output.unit, record.input.unit) if u)
    g_new, g_nom = refit.dc_gain(), nominal.dc_gain()
    gains = (f", DC gain {format_parameter(g_new)}{' ' + unit if unit else ''} against {format_parameter(g_nom)} "
             f"nominal ({g_new / g_nom:.2f} x)" if np.isfinite(g_new) and np.isfinite(g_nom) and g_nom != 0 else "")
    return f"re-fitted {refit.to_string(4)}{gains}"


def verdict_sentence(verdict: dict[str, Any], attribution: EffectDiagnosis, nrmse: float, nominal: Plant,
                     record: Record) -> str:
    """The verdict (``status`` none, effect, parameter_mismatch or unexplained) in one or two sentences.

    Parameters
    ----------
    verdict : dict
        The attribution's verdict (``status``, ``effects``, ``indistinguishable``).
    attribution : EffectDiagnosis
        The held-out attribution (effects, re-fit, noise floor).
    nrmse : float
        The gap: the nominal model's NRMSE on the record.
    nominal : Plant
        The nominal model.
    record : Record
        The record (its units).

    Returns
    -------
    str

    Examples
    --------
    >>> from synth.gap.diagnose import diagnose
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 12, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("1.5/(0.3*s+1)"), t, u) + 0.005 * np.random.default_rng(0).normal(size=t.size)
    >>> d = diagnose(Plant.from_string("2/(0.3*s+1)"), (t, u, y), candidates=["delay"], n_null=5)
    >>> verdict_sentence(d.verdict, d.attribution, d.localization.residual.nrmse, d.plant, d.record)[:60]
    'The gap (33 % NRMSE) is a parameter mismatch: re-fitting the'
    """
    status = verdict["status"]
    gap = f"{100 * nrmse:.0f} % NRMSE"
    if status == "none":
        ratio = attribution.j_nominal / attribution.noise_floor
        return (f"No gap beyond the measurement noise (gap {gap})." if ratio < CONCENTRATED_RATIO else
                f"No consistent gap (gap {gap}): the held-out error is {ratio:.3g} times the noise floor, but it "
                "comes from a few segments of the record.")
    if status == "effect":
        best = next(e for e in attribution.effects if e.effect == verdict["effects"][0])
        name = best.effect.replace("_", " ")
        # a center or scale the record fixes stays out; a fitted one (it has an interval) is shown
        params = ", ".join(f"{k} = {format_parameter(x)}" for k, x in best.parameters.items()
                           if k not in ("center", "scale") or k in best.parameter_ci)
        refit_share = refit_share_of_gap(attribution.refit_shrinkage, attribution.j_nominal, attribution.noise_floor)
        joint = plant_from_values(nominal, best.nominal, best.nominal.get("delay", nominal.delay))
        if refit_share >= MOSTLY_REFIT and response_change(joint, nominal) >= CHANGED:
            text = (f"The gap ({gap}): re-fitting the nominal coefficients alone removes "
                    f"{np.floor(1e4 * refit_share) / 100:g} % of the held-out error above the noise floor; beyond the "
                    f"re-fit, {name} ({params}) shrinks it by a further {100 * best.shrinkage:.0f} % and is the verdict. "
                    f"Re-fitted with it, the model changes ({refit_text(joint, nominal, record)}): a parameter "
                    "mismatch, or the share of another effect the linear part takes.")
        else:
            text = (f"The gap ({gap}) is explained by {name} ({params}): it removes {100 * best.share_of_gap:.0f} % of "
                    "the held-out error above the noise floor.")
        if verdict["indistinguishable"]:
            text += " The data cannot tell it from " + ", ".join(verdict["indistinguishable"][0][1:]) + "."
        left = min((e.j_heldout for e in attribution.effects if e.accepted), default=best.j_heldout)
        if left > LEFT_OVER * attribution.noise_floor:
            text += (f" What is left is still {left / attribution.noise_floor:.3g} times the noise floor: more than "
                     "this is missing (another effect, the model's structure, or a record that does not start at "
                     "rest).")
        return text
    if status == "parameter_mismatch":
        return (f"The gap ({gap}) is a parameter mismatch: re-fitting the nominal coefficients closes it (held-out "
                f"shrinkage {attribution.refit_shrinkage:.2f}; {refit_text(attribution.refit.plant, nominal, record)}).")
    return (f"The gap ({gap}) is not explained by the candidate effects"
            + (" (re-fitting the nominal coefficients helps, but the gap remains)."
               if verdict["effects"] == ["parameter_mismatch"] else "."))
