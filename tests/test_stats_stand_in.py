"""Parts of scipy.stats without its import (synth.stats_stand_in): cvxpy's import through the loader
(synth.synthesis.cvxpy_loader) and the exact search's Sobol points; each in a fresh interpreter, the stand-in
leaving no trace and the real package working afterwards."""

import subprocess
import sys

CVXPY = """
import sys
import synth.synthesis.convex  # imports cvxpy through the loader
print("stats loaded by cvxpy:", "scipy.stats" in sys.modules)
import cvxpy as cp, numpy as np
qre = sys.modules["cvxpy.atoms.quantum_rel_entr"]
print("entropy:", round(float(qre.entropy([0.25, 0.75])), 9))
import scipy.stats
print("real module:", hasattr(scipy.stats, "norm"), "scipy.stats" in sys.modules, scipy.stats is sys.modules["scipy.stats"])
x = cp.Variable(2)
p = cp.Problem(cp.Minimize(cp.sum_squares(x - np.array([1.0, -2.0]))), [x >= 0])
p.solve(solver=cp.CLARABEL)
print("solve:", p.status, [round(float(v), 6) for v in x.value])
"""

SOBOL = """
import sys
from synth.stats_stand_in import sobol_points
a = sobol_points(3, 16, seed=7)
print("stats loaded:", "scipy.stats" in sys.modules)
import scipy.stats
b = scipy.stats.qmc.Sobol(3, scramble=True, seed=7).random(16)
print("same points:", bool((a == b).all()))
print("real package:", scipy.stats is sys.modules["scipy.stats"], round(float(scipy.stats.norm.ppf(0.975)), 6))
print("qmc reused:", scipy.stats.qmc is sys.modules["scipy.stats.qmc"])
normal = scipy.stats.qmc.MultivariateNormalQMC([0.0], seed=1).random(4)  # calls scipy.stats.norm
print("qmc uses the real package:", float(normal.std()) > 0)
"""


def _printed(code: str) -> dict[str, str]:
    """What ``code`` printed in a fresh interpreter, as ``{label: value}`` (lines ``label: value``)."""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    return dict(line.split(": ", 1) for line in out.strip().splitlines())


def test_cvxpy_imports_without_scipy_stats_and_leaves_the_real_module() -> None:
    lines = _printed(CVXPY)
    assert lines["stats loaded by cvxpy"] == "False"
    # -(0.25 ln 0.25 + 0.75 ln 0.75), the real scipy.stats.entropy behind the stand-in's function
    assert lines["entropy"] == "0.562335145"
    assert lines["real module"] == "True True True"
    assert lines["solve"] == "optimal [1.0, 0.0]"


def test_sobol_points_load_without_scipy_stats_and_leave_the_real_package() -> None:
    lines = _printed(SOBOL)
    assert lines["stats loaded"] == "False"
    assert lines["same points"] == "True"
    assert lines["real package"] == "True 1.959964"
    assert lines["qmc reused"] == "True"
    assert lines["qmc uses the real package"] == "True"
