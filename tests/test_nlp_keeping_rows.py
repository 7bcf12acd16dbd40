"""The polish's stability keeping (|1 + L| >= level on the grid) is left out where a peak |S| bound already holds
|1 + L| further from zero on the same points: the same designs from fewer rows (a robust PI's 2,835 rows were a
third keeping rows, and IPOPT's time grows with the rows)."""

from __future__ import annotations

import numpy as np
import pytest

import synth.synthesis.nlp as nlp
import synth.synthesis.nlp_problem as nlp_problem
from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements import PeakSensitivity

GRID = np.geomspace(0.01, 1e3, 250)
PLANT = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
BOUNDS = {"kp": (0.0, 10.0), "ki": (0.0, 200.0)}


def _polished(monkeypatch, level: float = 0.05) -> tuple[Controller, list[int]]:
    """The polish of a PI under peak |S| <= 6 dB (|1 + L| >= 0.501), maximizing ki; its rounds' row counts."""
    rows: list[int] = []
    original = nlp_problem.NLPBuilder.solve

    def counting(self, *args, **kwargs):
        rows.append(len(self.lbg))
        return original(self, *args, **kwargs)

    monkeypatch.setattr(nlp_problem.NLPBuilder, "solve", counting)
    result = nlp.polish([PeakSensitivity(max_db=6.0)], [PLANT], Controller("PI", {"kp": 1.0, "ki": 20.0}), BOUNDS,
                        [("integral_gain", "maximize", 1.0)], GRID, stability_level=level)
    monkeypatch.setattr(nlp_problem.NLPBuilder, "solve", original)
    assert result.success
    return result.controller, rows


def test_the_rows_are_left_out_only_where_the_peak_bound_implies_them(monkeypatch):
    """Keeping at 0.05 (implied by |1 + L| >= 0.501): no rows; at 0.6 (not implied): one per grid point."""
    implied, implied_rows = _polished(monkeypatch, 0.05)
    _, kept_rows = _polished(monkeypatch, 0.6)
    assert kept_rows[0] - implied_rows[0] == GRID.size
    closest = float(np.min(np.abs(1.0 + Loop(PLANT, implied).L(GRID))))
    assert closest >= 0.5  # the design keeps |1 + L| far above 0.05 on the grid all the same


def test_the_same_design_as_with_the_redundant_rows(monkeypatch):
    """With the rows forced back in (the peak bound's type hidden from the test of redundancy), the polish ends at
    the same design, to IPOPT's tolerance."""
    without, without_rows = _polished(monkeypatch)

    class Unrelated:  # isinstance(requirement, Unrelated) is never true: every keeping row is added, as before
        pass

    monkeypatch.setattr(nlp, "PeakSensitivity", Unrelated)
    with_rows, rows = _polished(monkeypatch)
    assert rows[0] - without_rows[0] == GRID.size
    assert without.parameters["ki"] == pytest.approx(with_rows.parameters["ki"], rel=1e-6)
    assert without.parameters["kp"] == pytest.approx(with_rows.parameters["kp"], rel=1e-6)
