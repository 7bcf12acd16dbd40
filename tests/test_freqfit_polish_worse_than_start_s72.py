"""A formula fit's last polish (its delay freed) that ends worse than the point it started from is not the answer:
that start, the best fixed-delay local optimum, is a point of the polish's own problem. The test makes IPOPT's
delay-free polish end at the point where a CI test worker's fit of ``tests/test_freqfit_nmp_start_s71.py`` (seed 0)
ended (a pole at 2.85e10 rad/s standing in for a 0.058 s delay, J = 103) and checks that the fit still finds the zero.
That worker's failure itself came from a bad matched start (``tests/test_freqfit_matched_start_signs_s72.py``); this
guards the other way such a fit can be lost."""

from __future__ import annotations

import casadi
import numpy as np
from scipy import signal

from synth.data import record_from_arrays
from synth.ident.freqfit import fit_frequency_response
from synth.ident.spectra import frequency_response

CI_POINT = [-1.00007541e10, -2.61377047, 2.84827353e10, 1.42024966, 0.0582053145522522]  # c, z, p1, p2, Td


def _response():
    fs, gain, zero, p1, p2 = 200.0, 4.3128, 2.8317, 1.6256, 12.0363  # gain (zero - s)/((s+p1)(s+p2))
    t = np.arange(24000) / fs
    u = signal.chirp(t, 0.1, t[-1], 5.0, method="logarithmic")
    b, a, _ = signal.cont2discrete(([-gain, gain * zero], np.polymul([1.0, p1], [1.0, p2])), 1 / fs, method="zoh")
    y = signal.lfilter(np.squeeze(b), a, u)
    y = y + 0.05 * np.std(y) * np.random.default_rng(0).standard_normal(y.size)
    return frequency_response(record_from_arrays(t, u, y))


class _LostPolish:
    """IPOPT's answer replaced by the CI's point (its status "acceptable")."""

    def __init__(self, solver):
        self.solver = solver

    def __call__(self, **kwargs):
        answer = dict(self.solver(**kwargs))
        answer["x"] = casadi.DM(CI_POINT)
        return answer

    def stats(self):
        return {**self.solver.stats(), "return_status": "Solved_To_Acceptable_Level"}


def test_a_polish_that_ends_worse_than_its_start_leaves_the_start(monkeypatch):
    real = casadi.nlpsol

    def nlpsol(name, plugin, problem, options):
        solver = real(name, plugin, problem, options)
        return _LostPolish(solver) if name == "freqfit" and problem["x"].numel() == len(CI_POINT) else solver

    resp = _response()
    monkeypatch.setattr(casadi, "nlpsol", nlpsol)
    fit = fit_frequency_response(resp, "c*(s+z)*exp(-Td*s)/((s+p1)*(s+p2))")
    assert abs(fit.parameters["z"] + 2.8317) < 0.1 * 2.8317, fit.parameters
    assert np.allclose(sorted([fit.parameters["p1"], fit.parameters["p2"]]), [1.6256, 12.0363], rtol=0.15)
    assert 0.0 <= fit.parameters["Td"] < 0.02  # the grid's delay, not the lost polish's 0.058 s
    assert fit.fit_percent > 95.0
