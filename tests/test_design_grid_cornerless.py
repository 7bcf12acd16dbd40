"""The design grid and the rational controllers' scale of a plant without corner frequencies (``k / s``, ``k / s^2``):
the design benchmark's seed 19 #35 (a rational controller of order (2, 3) on ``4.59 e^(-0.00023 s) / s``, |S| <= -22 dB
below 0.342 rad/s, peak |T| and |KS| bounds) answered "infeasible" where the reference met every requirement. The
plant's only "corner" was ``1 / delay``: the grid ran from 43 to 430,000 rad/s, with no point in the band of the
sensitivity bound (a band from 0 did not lower the grid), and the coefficients were scaled at 4,300 rad/s (``b0``'s
range in the convex stage's units, +-3e-8, under the solver's tolerance)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.plant import Plant
from synth.requirements import PeakComplementary, Sensitivity
from synth.spec import parse_spec
from synth.synthesis.convex_settings import ConvexSettings, design_grid
from synth.synthesis.parametrization import reference_frequency
from synth.unity_gain import unity_gain_frequency

PLANT = Plant.from_string("4.59214/s", delay=0.000232547)
BAND = Sensitivity(max_db=-21.9987, band=(0.0, 0.341965))


def test_a_plant_without_corners_is_gridded_around_its_unity_gain_frequency():
    grid = design_grid([PLANT], [PeakComplementary(max_db=3.6)], ConvexSettings())
    assert grid[0] <= 4.59214 / 100 * (1 + 1e-9) and grid[-1] >= 1 / 0.000232547
    assert np.count_nonzero((grid > 4.59214 / 10) & (grid < 4.59214 * 10)) >= 2 * ConvexSettings().per_decade - 2


def test_a_band_from_zero_has_grid_points_in_it():
    grid = design_grid([Plant.from_string("1/(s+100)")], [BAND], ConvexSettings())  # the plant's range: 1-10,000
    inside = grid[grid <= 0.341965]
    assert inside.size >= 2 * ConvexSettings().per_decade - 2 and inside[0] <= 0.341965 / 100 * (1 + 1e-9)


@pytest.mark.parametrize(("tf", "delay", "expected"), [("4.59214/s", 0.000232547, 4.59214), ("4/s^2", 0.0, 2.0),
                                                       ("4/s^2", 2.0, 0.5)])
def test_the_scale_of_rational_coefficients_is_where_the_plant_crosses_unity_gain(tf, delay, expected):
    spec = parse_spec({"name": "r", "plant": {"tf": tf, "delay": delay}, "requirements": [
        {"type": "peak_complementary", "max_db": 3.6}], "controller": {"type": "rational", "order": [2, 3]}})
    assert reference_frequency(spec) == pytest.approx(expected, rel=1e-12)


def test_plants_with_corners_or_a_pure_gain_have_no_unity_gain_frequency():
    assert unity_gain_frequency(np.array([1.0]), np.array([1.0, 1.0, 0.0])) is None  # a corner at 1 rad/s
    assert unity_gain_frequency(np.array([3.0]), np.array([1.0])) is None
    assert unity_gain_frequency(np.array([2.0, 0.0]), np.array([1.0])) == pytest.approx(0.5)


def test_an_infeasible_rational_design_names_its_active_bounds_in_the_parameters_units():
    """The convex stage works on coefficients scaled by powers of the reference frequency (100 rad/s here); the
    diagnosis printed those (``b0 <= 0.005``, ``a0 >= 0.01``, seed 19 #35's ``b0 <= 3.05332e-08``), not the bounds
    the spec wrote."""
    from synth.design import design

    spec = parse_spec({"name": "r", "plant": {"tf": "1/(s+100)"}, "controller": {"type": "rational", "order": [0, 1],
                       "bounds": {"b0": [-0.5, 0.5], "a0": [1, 10]}},
                       "requirements": [{"type": "sensitivity", "max_db": -20, "band": [0, 1]}]})
    assert reference_frequency(spec) == pytest.approx(100.0)
    d = design(spec)
    assert d.status == "infeasible"
    assert "Active parameter bounds: b0 <= 0.5, a0 >= 1." in d.verdict
