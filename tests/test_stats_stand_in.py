"""Sobol points without scipy.stats's import (synth.stats_stand_in): the same points, and no trace left."""

import subprocess
import sys

CODE = """
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


def test_sobol_points_load_without_scipy_stats_and_leave_the_real_package() -> None:
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, check=True).stdout
    lines = dict(line.split(": ", 1) for line in out.strip().splitlines())
    assert lines["stats loaded"] == "False"
    assert lines["same points"] == "True"
    assert lines["real package"] == "True 1.959964"
    assert lines["qmc reused"] == "True"
    assert lines["qmc uses the real package"] == "True"
