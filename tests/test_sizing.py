"""Rotor and drive sizing by momentum theory (X-4 paper, sections 2-3) and its reconciliation rows."""

from __future__ import annotations

import math

import pytest

from synth.errors import ModelError
from synth.paper_row import AGREES, APPROXIMATE, DERIVED, DISAGREES, PaperRow, printed_tolerance, rows_table
from synth.sizing import (
    RHO_SEA_LEVEL,
    density_for_power,
    isa_altitude,
    rotor_sizing,
    sizing_checks,
    thrust_for_power,
)


def test_momentum_theory_numbers():
    s = rotor_sizing(thrust=12.7)
    area = math.pi * 0.165**2
    assert s.area == pytest.approx(area)
    assert s.induced_power == pytest.approx(12.7**1.5 / math.sqrt(2 * 1.225 * area))
    assert s.induced_power == pytest.approx(98.87, abs=0.01)
    assert s.induced_velocity * s.thrust == pytest.approx(s.induced_power)  # P_i = T v_i
    assert s.torque_constant == pytest.approx(0.1749 / 22)
    assert s.shaft_power == pytest.approx(0.1749 * 800)
    assert s.battery_voltage == pytest.approx(14.8) and s.battery_current == pytest.approx(24.0)
    assert s.electrical_power_at_limit == pytest.approx(14.8 * 22)
    # the thrust the shaft power lifts at FM = 1 inverts eq. 1
    assert rotor_sizing(thrust=s.max_thrust_ideal).induced_power == pytest.approx(s.shaft_power)


def test_default_thrust_is_craft_weight_with_margin():
    assert rotor_sizing().thrust == pytest.approx(4.0 * 9.80665 * 1.3 / 4)
    assert rotor_sizing(mass=2.0, margin=0.0, rotors=2, g=10.0).thrust == pytest.approx(10.0)


def test_every_number_has_a_unit():
    d = rotor_sizing().to_dict()
    assert all(set(v) == {"value", "unit"} and v["unit"] for v in d.values())
    assert d["induced_power"]["unit"] == "W" and d["max_torque"]["unit"] == "N m" and d["rho"]["unit"] == "kg/m^3"


def test_density_and_thrust_inverses():
    rho = density_for_power(12.7, 0.165, 101.2)
    assert rho == pytest.approx(1.169, abs=0.001)
    assert rotor_sizing(thrust=12.7, rho=rho).induced_power == pytest.approx(101.2)
    assert thrust_for_power(131.0, 0.165, rho) == pytest.approx(15.08, abs=0.01)
    assert 400 < isa_altitude(rho) < 600
    assert isa_altitude(RHO_SEA_LEVEL) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("kw", [{"radius": 0}, {"rho": -1}, {"speed": float("nan")}, {"margin": -0.1},
                                {"thrust": 0.0}])
def test_bad_input_is_a_model_error(kw):
    with pytest.raises(ModelError, match="sizing: "):
        rotor_sizing(**kw)


def test_the_three_stated_non_reconciliations():
    rows = {r.quantity: r for r in sizing_checks()}
    # 131 W = 0.1749 N m x 749 rad/s, not 800
    speed = rows["shaft power 131 W / 0.1749 N m: speed"]
    assert speed.synth == pytest.approx(131 / 0.1749) and speed.status == DISAGREES
    assert 745 < speed.synth < 755
    assert rows["top shaft power at 800 rad/s"].synth == pytest.approx(139.92, abs=0.01)
    # 101.2 W implies rho ~ 1.17; sea level gives 98.9 W
    power = rows["induced power for 12.7 N"]
    assert power.synth == pytest.approx(98.87, abs=0.01) and power.status == DISAGREES
    assert rows["air density implied by 101.2 W"].synth == pytest.approx(1.169, abs=0.001)
    assert rows["air density implied by 101.2 W"].status == DERIVED
    # 22 A in section 3 against 2 x 12 A in section 2
    current = rows["current limit"]
    assert current.paper == "22" and current.synth == pytest.approx(24.0) and current.status == DISAGREES


def test_other_sizing_rows():
    rows = {r.quantity: r for r in sizing_checks()}
    assert rows["thrust per rotor"].status == AGREES
    assert rows["largest ideal thrust at 131 W (FM = 1)"].synth == pytest.approx(15.32, abs=0.01)
    assert rows["least figure of merit"].synth == pytest.approx(98.87 / 131, abs=1e-3)
    assert rows["built rotor: shaft power (14.3 N, FM 0.71)"].synth > 131
    assert rows["hover speed of the built rotor (T ~ w^2)"].status == APPROXIMATE
    for q in ("battery voltage", "battery current", "cells for four drives"):
        assert rows[q].status == AGREES
    # at the implied density the paper's 101.2 W, 15.1 N and FM 0.77 all reconcile
    at_implied = {r.quantity: r for r in sizing_checks(rho=density_for_power(12.7, 0.165, 101.2))}
    for q in ("induced power for 12.7 N", "largest ideal thrust at 131 W (FM = 1)", "least figure of merit"):
        assert at_implied[q].status == AGREES, q


def test_paper_row_helpers():
    assert printed_tolerance("-16.12") == pytest.approx(0.005)
    r = PaperRow.compare("a", "10", 10.4, "W", "s", "n")
    assert r.status == AGREES and r.reconciles
    assert PaperRow.compare("a", "10", 11, "W", "s", "n", approximate=True).status == APPROXIMATE
    assert PaperRow.derived("b", 1.0, "A", "s", "n").difference is None
    table = rows_table([r])
    assert table.count("\n") == 2 and "| a | 10 | 10.4 | W | reconciles |" in table
    assert set(r.to_dict()) >= {"paper", "synth", "unit", "source", "status", "reconcile"}
