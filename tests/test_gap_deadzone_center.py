"""A dead zone whose band is not where the command starts is named, located and sized (the defect of session 59:
the center was held at the command's first sample, and such records were named a quantizer, a saturation or a
parameter mismatch).

The records (``benchmarks/gap/deadzone_center.py``) are simulated by scipy alone, not by synth: random second-order
plants, a smooth random command, the band 1.5-3 units from where the command starts (``off``) or around it
(``rest``). A band at rest keeps the center held there: the fitted center is kept only when it lowers the training
SSR by more than the 95 % likelihood-ratio point, so it is not a second parameter counted against the dead zone.
"""

from __future__ import annotations

import pytest

from benchmarks.gap.deadzone_center import CANDIDATES, records
from synth.gap.attribution.parsimony import free_parameters
from synth.gap.attribution.refit import fit_augmented
from synth.gap.diagnose import diagnose
from synth.gap.effects import DeadzoneEffect


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0])
def test_an_off_center_dead_zone_is_named_with_its_center(seed: int) -> None:
    nominal, rec, val, center, width = records(seed, "off")
    d = diagnose(nominal, rec, val, candidates=CANDIDATES, n_boot=200)
    assert d.verdict["effects"] == ["deadzone"], d.summary
    found = next(e for e in d.attribution.effects if e.effect == "deadzone").parameters
    assert abs(found["center"] - center) < 0.2, (found, center)
    assert abs(found["width"] - width) < 0.1 * width, (found, width)
    assert f"center = {found['center']:.4g}" in d.summary  # a fitted center is part of the headline


@pytest.mark.parametrize("seed", [3])
def test_a_band_at_rest_keeps_its_center_held_and_counts_one_parameter(seed: int) -> None:
    nominal, rec, _, center, width = records(seed, "rest")
    fit = fit_augmented(nominal, rec.t, rec.u, rec.y, DeadzoneEffect())
    assert fit.effect.center_search == "rest"
    assert fit.params["center"] == rec.u[0] == center
    assert abs(fit.params["width"] - width) < 0.1 * width
    assert free_parameters(fit.effect, fit.params) == 1


def test_a_band_away_from_rest_is_fitted_and_counts_two_parameters() -> None:
    nominal, rec, _, center, width = records(1, "off")
    fit = fit_augmented(nominal, rec.t, rec.u, rec.y, DeadzoneEffect())
    assert fit.effect.center_search == "fitted"
    assert abs(fit.params["center"] - center) < 0.2 and abs(fit.params["width"] - width) < 0.1 * width
    assert free_parameters(fit.effect, fit.params) == 2
    held = fit_augmented(nominal, rec.t, rec.u, rec.y, DeadzoneEffect(center_search="rest"))
    assert held.params["center"] == rec.u[0] and held.ssr > 10 * fit.ssr


def test_a_command_with_no_band_to_pass_through_gets_the_dead_zone_at_rest_not_a_crash():
    """A command at rest for 96 % of the record: every decile is the rest value, and no band there has samples on
    both sides (not admissible), so the fitted form has no start and the band at rest is the answer."""
    import numpy as np

    from synth.plant import Plant

    t = np.arange(0, 20, 0.01)
    u = np.where(t >= 19.2, 1.0, 0.0)
    G = Plant.from_string("2/(0.3*s+1)")
    assert DeadzoneEffect(center_search="fitted").grid(t, u, G) == []
    y = DeadzoneEffect().apply(G, t, u, {"width": 0.3, "center": 0.0})
    y = y + 0.01 * np.random.default_rng(0).normal(size=t.size)
    fit = fit_augmented(G, t, u, y, DeadzoneEffect())
    assert fit.effect.center_search == "rest" and fit.params["center"] == 0.0  # (one step: its width is a gain)
    assert fit.ssr < 2.0 * t.size * 0.01**2  # at the noise
