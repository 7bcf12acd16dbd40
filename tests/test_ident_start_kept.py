"""A start that is already the optimum, kept where the solver ends above it (synth.ident.start_kept, issue 16 item 2).

A solver stopped at its iteration limit a little above its start used to fail the fit ("ended worse than its
start"), although the start itself was converged. Here the solvers are replaced by one that drifts uphill by a
small step (what IPOPT and Levenberg-Marquardt did along a nearly cancelling pair: 98.10710 % against 98.10713 %
at the start), so that the rule itself is tested: a converged start is the fit, a start that is not stays a
failure. The converged start is the least-squares optimum found by an unpatched fit of the same record.
"""

from __future__ import annotations

import io
from contextlib import redirect_stdout

import numpy as np
import pytest

from synth.cli import main
from synth.data.record import Record
from synth.errors import FitError
from synth.ident import timefit
from synth.ident.convolution_problem import ConvolutionProblem
from synth.ident.sim_error_problem import SimulationErrorProblem
from synth.ident.start_kept import START_CONVERGED
from synth.ident.timefit import fit_structure

DT = 0.01


@pytest.fixture(scope="module")
def record() -> Record:
    """Steps through ``2/(s + 1.5)`` (exact zero-order-hold samples) with white noise of std 0.01."""
    rng = np.random.default_rng(3)
    n = 800
    u = np.repeat(rng.uniform(-1.0, 1.0, n // 100), 100)
    u[:50] = 0.0
    a = np.exp(-1.5 * DT)
    y = np.zeros(n)
    for k in range(1, n):
        y[k] = a * y[k - 1] + 2.0 / 1.5 * (1.0 - a) * u[k - 1]
    return Record(t=np.arange(n) * DT, u=u, y=y + 0.01 * rng.normal(size=n))


def _uphill(monkeypatch: pytest.MonkeyPatch, record: Record, start: dict[str, float]) -> None:
    """The deterministic start made ``start`` (its offset included), and every solver ending at its start times
    ``1 + 2e-3`` with the true SSR there, at its iteration limit."""
    y_ref = float(np.mean(record.y[:int(np.flatnonzero(record.u != record.u[0])[0])]))
    monkeypatch.setattr(timefit, "linear_initial_model",
                        lambda *args: (np.array([1.0]), np.array([1.0, 1.0]), 0.0, start["offset"] - y_ref))
    monkeypatch.setattr(timefit, "map_to_structure", lambda *args: np.array([start["k"], start["p"]]))

    def solve(self, x0, par, *args, **kwargs):
        x = np.asarray(x0, float) * (1.0 + 2e-3)
        r = record.y - np.asarray(self.yhat_fn(x, par)).ravel()
        return x, float(r @ r), {"status": "Maximum_Iterations_Exceeded", "iterations": 100, "success": False}

    for problem in (SimulationErrorProblem, ConvolutionProblem):
        monkeypatch.setattr(problem, "solve", solve)


def test_a_converged_start_is_the_fit_when_the_solver_ends_above_it(record, monkeypatch):
    best = fit_structure(record, "k/(s+p)", check=True)
    assert best.solver["status"] == "Solve_Succeeded"
    optimum = {"k": best.parameters["k"], "p": best.parameters["p"], "offset": best.offset}
    _uphill(monkeypatch, record, optimum)
    kept = fit_structure(record, "k/(s+p)", check=True)
    assert kept.solver["status"] == START_CONVERGED and kept.solver["success"]
    assert "the start kept: the solver ended above it (Maximum_Iterations_Exceeded" in kept.solver["method"]
    for name in ("k", "p"):  # the start itself, with the optimum's uncertainty
        assert kept.parameters[name] == pytest.approx(optimum[name], rel=1e-12)
        assert kept.std[name] == pytest.approx(best.std[name], rel=0.02)
    assert kept.fit_percent == pytest.approx(best.fit_percent, abs=1e-6)


def test_a_start_that_is_no_optimum_still_fails(record, monkeypatch):
    best = fit_structure(record, "k/(s+p)", check=True)
    # five standard errors off in the gain: a Gauss-Newton step from there gains about five
    off = {"k": best.parameters["k"] + 5.0 * best.std["k"], "p": best.parameters["p"], "offset": best.offset}
    _uphill(monkeypatch, record, off)
    with pytest.raises(FitError, match=r"(IPOPT|Levenberg-Marquardt) stopped with Maximum_Iterations_Exceeded"):
        fit_structure(record, "k/(s+p)", check=True)


def test_the_solver_status_is_known_to_the_fit_module():
    assert timefit.START_CONVERGED == START_CONVERGED == "Start_Converged"


def test_the_command_line_says_the_start_was_kept(record, monkeypatch, tmp_path):
    best = fit_structure(record, "k/(s+p)", check=True)
    _uphill(monkeypatch, record, {"k": best.parameters["k"], "p": best.parameters["p"], "offset": best.offset})
    path = tmp_path / "r.csv"
    np.savetxt(path, np.column_stack([record.t, record.u, record.y]), delimiter=",", header="t,u,y", comments="")
    out = io.StringIO()
    with redirect_stdout(out):
        code = main(["identify", "--data", str(path), "--time", "t", "--input", "u", "--output", "y", "--structure",
                     "k/(s+p)", "--average", "none", "--no-figures", "--out", str(tmp_path / "rep")])
    assert code == 0
    assert "the start kept (IPOPT ended above it after 100 iterations)" in out.getvalue() \
        or "the start kept (Levenberg-Marquardt ended above it after 100 iterations)" in out.getvalue(), out.getvalue()
