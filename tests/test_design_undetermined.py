"""A design whose search finds no stabilizing controller answers "undetermined", with its evidence; where the
bounds are shown to hold none (a PI's plane, synth.synthesis.stabilizing_plane), "infeasible", with the proof.

Before, such a spec ended in a one-line error and exit 2 ("bad input"), although the spec is valid. The
plants here are ``k e^(-theta s)/(s - p)`` with ``theta p > 1``: a known result for a first-order unstable
plant with delay is that no proportional gain stabilizes it when the delay exceeds the unstable time constant
(``theta > 1/p``), and integral action only takes phase away. The test checks that independently of synth,
by the exact Nyquist condition for P (the critical frequency solves ``w = -p tan(w theta)``), before asking
synth.
"""

import json

import numpy as np
import pytest
from scipy.optimize import brentq

from synth import design, parse_spec
from synth.cli import main


def _spec(k: float, p: float, theta: float) -> dict:
    return {"name": "unstabilizable", "plant": {"tf": f"{k:.6g}/(s-{p:.6g})", "delay": theta},
            "controller": {"type": "PI", "bounds": {"kp": [0.0, 10.0 * p / k], "ki": [0.01, 5.0]}},
            "requirements": [{"type": "margins", "phase_margin_deg": 30.0}],
            "objective": {"maximize": "bandwidth"}}


def _p_stabilizable(k: float, p: float, theta: float) -> bool:
    """Is some kp > 0 stabilizing for ``kp k e^(-theta s)/(s - p)``? Nyquist: with one unstable open-loop pole
    the curve must circle -1 once. It starts at ``-kp k/p`` on the negative real axis (so ``kp k > p``) and
    next meets that axis at ``w*`` where ``atan(w/p) = w theta``, with modulus ``kp k/|j w* - p|``, which must
    be below 1. A ``kp`` exists iff that crossing exists in (0, pi/(2 theta))."""
    def phase(w: float) -> float:  # arg L(jw) + pi
        return float(np.arctan2(w, p) - w * theta)

    ws = np.linspace(1e-9, np.pi / (2 * theta), 20001)
    values = np.array([phase(w) for w in ws])
    changes = np.flatnonzero(values[:-1] * values[1:] < 0)
    if changes.size == 0:
        return False
    w_star = brentq(phase, ws[changes[0]], ws[changes[0] + 1])
    return bool(w_star > 0)  # then any kp k in (p, |j w* - p|) stabilizes


@pytest.mark.parametrize("seed", range(3))
def test_a_plant_no_pi_in_the_bounds_stabilizes_gets_an_infeasible_design_with_the_proof(seed):
    rng = np.random.default_rng(40 + seed)
    p, k = float(rng.uniform(0.3, 3.0)), float(rng.uniform(0.5, 5.0))
    theta = float(rng.uniform(1.2, 3.0)) / p
    assert not _p_stabilizable(k, p, theta)
    assert _p_stabilizable(k, p, 0.5 / p)  # the reference can say yes
    result = design(parse_spec(_spec(k, p, theta)))
    assert result.status == "infeasible" and not result.feasible and result.controller is None
    assert "No controller in the bounds stabilizes the loop" in result.verdict and "D-decomposition" in result.verdict
    data = result.to_dict()
    assert data["status"] == "infeasible" and data["infeasible"]["reason"] == "no stabilizing controller"


@pytest.mark.parametrize("seed", [0, 2])
def test_a_structure_the_plane_does_not_decide_stays_undetermined(seed):
    """A lead-lag (not affine in its gain and zero together) on the same plants, whose search finds no stabilizing
    one (seed 1's shorter delay, ``theta p = 1.43``, leaves room for a lead's phase: a lead-lag is found there):
    only searched, so "undetermined"."""
    rng = np.random.default_rng(40 + seed)
    p, k = float(rng.uniform(0.3, 3.0)), float(rng.uniform(0.5, 5.0))
    theta = float(rng.uniform(1.2, 3.0)) / p
    spec = {**_spec(k, p, theta), "controller": {"type": "leadlag", "bounds": {"k": [0.0, 10.0 * p / k],
                                                                              "z": [0.1, 10.0], "p": [1.0, 50.0]}}}
    result = design(parse_spec(spec))
    assert result.status == "undetermined" and not result.feasible and result.controller is None
    assert "600 random controllers" in result.verdict and "does not prove" in result.verdict
    data = result.to_dict()
    assert data["status"] == "undetermined" and data["undetermined"]["reason"] == "no stabilizing start"


def _designed(tmp_path, capsys, controller: str) -> tuple[int, str, dict, str]:
    """``synth design`` on ``1/(s-1)`` behind 2 s with ``controller`` (YAML): exit code, output, result.json, HTML."""
    spec = tmp_path / "u.yaml"
    spec.write_text("name: u\nplant: {tf: \"1/(s-1)\", delay: 2.0}\ncontroller: " + controller + "\nrequirements:\n"
                    "  - {type: margins, phase_margin_deg: 30}\nobjective: {maximize: bandwidth}\n", encoding="utf-8")
    code = main(["design", str(spec), "--out", str(tmp_path / "out")])
    data = json.loads((tmp_path / "out" / "result.json").read_text(encoding="utf-8"))
    return code, capsys.readouterr().out, data, (tmp_path / "out" / "report.html").read_text(encoding="utf-8")


def test_cli_exit_1_and_a_report_with_the_proof(tmp_path, capsys):
    code, out, data, html = _designed(tmp_path, capsys, "{type: PI, bounds: {kp: [0, 5], ki: [0.1, 5]}}")
    assert code == 1, out
    assert "u: INFEASIBLE" in out and "D-decomposition" in out
    assert data["status"] == "infeasible" and data["infeasible"]["reason"] == "no stabilizing controller"
    assert "<strong>Infeasible.</strong>" in html
    assert "not evaluated: no controller in the bounds stabilizes the loop" in html


def test_cli_exit_3_and_a_report_that_lists_the_requirements_as_not_evaluated(tmp_path, capsys):
    code, out, data, html = _designed(tmp_path, capsys, "{type: leadlag, bounds: {k: [0, 5], z: [0.1, 10], p: [1, 50]}}")
    assert code == 3, out  # before: exit 2, "found no stabilizing controller"
    assert "u: UNDETERMINED" in out
    assert data["status"] == "undetermined" and data["feasible"] is False
    assert "<strong>Undetermined.</strong>" in html and 'class="verdict warn"' in html
    assert "not evaluated: no controller in the bounds was found" in html
