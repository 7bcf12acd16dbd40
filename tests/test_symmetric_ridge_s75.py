"""A fit from the deterministic start that ends where exchangeable poles meet is restarted with them apart
(synth.ident.symmetric_ridge).

Random three-real-pole plants whose two fast poles lie within a factor 1.5 of each other, 30 s at 500 Hz, 5 % output
noise: SRIVC often returns the fast pair as a complex pair, mapped onto the real structure as a double pole. The
reference is the same fit started at the truth, an independent start; the records are simulated by scipy's
zero-order-hold ``lsim``, not by synth. Before the restart, seed 5 ended on the ridge at 7.661 / 7.661 (infinite
variances) below the reference's 6.555 / 9.117.
"""

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.ident.timefit import fit_structure

SEEDS = list(range(2, 10))
STRUCTURE = "k/((s+p1)*(s+p2)*(s+p3))"


def _record(seed: int) -> tuple[object, dict[str, float]]:
    rng = np.random.default_rng(7500 + seed)
    slow = rng.uniform(1.0, 3.0)
    mid = slow * rng.uniform(4.0, 8.0)
    poles = np.array([slow, 0.8 * mid, 1.2 * mid])
    k = float(np.prod(poles)) * rng.uniform(0.5, 3.0)
    dt = 0.002
    t = np.arange(0.0, 30.0, dt)
    hold = int(rng.uniform(2.0, 5.0) / slow / dt)
    u = np.repeat(rng.choice([-1.0, 1.0], size=t.size // hold + 1), hold)[:t.size]
    u[: hold // 2] = 0.0
    _, y, _ = signal.lsim(signal.lti([k], np.poly(-poles)), u, t, interp=False)
    y = y + rng.normal(0.0, 0.05 * np.std(y), t.size)
    return record_from_arrays(t, u, y), {"k": k, "p1": poles[0], "p2": poles[1], "p3": poles[2]}


@pytest.fixture(scope="module")
def fits() -> dict[int, tuple[object, object]]:
    out = {}
    for seed in SEEDS:
        record, truth = _record(seed)
        out[seed] = (fit_structure(record, STRUCTURE, delay=0.0), fit_structure(record, STRUCTURE, delay=0.0,
                                                                               initial=truth))
    return out


@pytest.mark.parametrize("seed", SEEDS)
def test_fit_reaches_the_optimum_a_start_at_the_truth_reaches(seed: int, fits: dict) -> None:
    fit, reference = fits[seed]
    assert fit.fit_percent >= reference.fit_percent - 1e-7
    poles = sorted(fit.parameters[p] for p in ("p1", "p2", "p3"))
    assert poles == pytest.approx(sorted(reference.parameters[p] for p in ("p1", "p2", "p3")), rel=1e-3)


def test_a_fit_on_the_ridge_is_restarted_and_says_so(fits: dict) -> None:
    restarted = [seed for seed, (fit, _) in fits.items() if "ridge_split" in fit.solver]
    assert restarted == [5]
    fit = fits[5][0]
    assert "moved 10% apart" in fit.solver["initialization"]
    assert np.all(np.isfinite([fit.std[p] for p in ("p1", "p2", "p3")]))
    assert abs(fit.parameters["p1"] - fit.parameters["p2"]) > 2 * max(fit.std["p1"], fit.std["p2"])
