"""cvxpy imported without scipy.stats (synth.synthesis.cvxpy_loader): the stand-in leaves no trace."""

import subprocess
import sys

CODE = """
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


def test_cvxpy_imports_without_scipy_stats_and_leaves_the_real_module():
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, check=True).stdout
    lines = dict(line.split(": ", 1) for line in out.strip().splitlines())
    assert lines["stats loaded by cvxpy"] == "False"
    # -(0.25 ln 0.25 + 0.75 ln 0.75), the real scipy.stats.entropy behind the stand-in's function
    assert lines["entropy"] == "0.562335145"
    assert lines["real module"] == "True True True"
    assert lines["solve"] == "optimal [1.0, 0.0]"
