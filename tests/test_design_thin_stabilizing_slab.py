"""A plant that only a narrow band of negative gains stabilizes: design finds a start and answers.

``(s - z)/((s - p)(s + q))`` with ``0 < p < z``: under P control the closed-loop polynomial is
``s^2 + (q - p + k) s - (p q + k z)``, stable exactly for ``p - q < k < -p q / z``. Inside PID bounds of
``[-10, 10]`` for each gain that slab (ki and kd near zero, kp in a band a few tenths wide) was missed by the
600 random starts, and ``synth design`` said "found no stabilizing controller in the bounds" with exit 2
(bad input), although the spec is valid and P(-1.75) stabilizes the first plant below. The reference here is
the Routh condition above and numpy's roots of the closed-loop polynomial, not synth's stability code.
"""

import numpy as np
import pytest

from synth import design, parse_spec
from synth.cli import main


def _spec(p: float, z: float, q: float) -> dict:
    return {"name": "slab", "plant": {"tf": f"(s-{z:.6g})/((s-{p:.6g})*(s+{q:.6g}))"},
            "controller": {"type": "PID", "bounds": {"kp": [-10, 10], "ki": [-5, 5], "kd": [0, 1],
                                                     "tf": [0.01, 0.01]}},
            "requirements": [{"type": "peak_sensitivity", "max_db": 30.0}]}


def _closed_loop_roots(controller, p: float, z: float, q: float) -> np.ndarray:
    num, den = controller.tf()
    return np.roots(np.polyadd(np.polymul(den, np.poly([p, -q])), np.polymul(num, [1.0, -z])))


def test_cli_designs_the_slab_plant_instead_of_refusing_the_spec(tmp_path, capsys):
    spec = tmp_path / "slab.yaml"
    spec.write_text("name: slab\nplant: {tf: \"(s-2)/((s-1)*(s+3))\"}\ncontroller: {type: PID, bounds: "
                    "{kp: [-10, 10], ki: [-5, 5], kd: [0, 1], tf: [0.01, 0.01]}}\nrequirements:\n"
                    "  - {type: peak_sensitivity, max_db: 30}\n", encoding="utf-8")
    code = main(["design", str(spec), "--no-report", "--quiet"])
    assert code == 0, capsys.readouterr().err  # before: exit 2, "found no stabilizing controller"


@pytest.mark.parametrize("seed", range(4))
def test_random_slab_plants_get_a_stabilizing_design(seed):
    rng = np.random.default_rng(100 + seed)
    p = float(rng.uniform(0.2, 2.0))
    z = float(p * rng.uniform(1.5, 4.0))
    q = float(rng.uniform(2.0, 10.0))
    lo, hi = p - q, -p * q / z  # the stabilizing gains under P control (Routh)
    assert lo < hi < 0
    result = design(parse_spec(_spec(p, z, q)))
    assert result.feasible, result.verdict
    roots = _closed_loop_roots(result.controller, p, z, q)
    assert np.max(roots.real) < 0, (result.controller, roots)
