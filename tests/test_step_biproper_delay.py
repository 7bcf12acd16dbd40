"""The step of a biproper loop behind a delay: its response jumps at the delay's multiples (a black-box test).

PI(0.5, 1) around (s + 2)/(s + 1) behind 0.2 s: |L(j inf)| = 0.5, so the output jumps each time the step
comes round the loop. The metrics were right to 1e-4, but the reported error was 0.062 of the final value
(larger than the 1.6 % overshoot): the bound on the linear interpolation between samples took an eighth of the
jump at times that lie on a sample, where the interpolation is exact. The reference is the method of steps
with scipy's solve_ivp, written here: on each delay interval the delayed command is the previous interval's
(dense output), the plant's state and the PI's integral are integrated, and the output is
``y = u(t - tau) + x`` ((s + 2)/(s + 1) = 1 + 1/(s + 1))."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.timeresp import linear_step

KP, KI, TAU, T_END = 0.5, 1.0, 0.2, 8.0


def _reference(t_out: np.ndarray) -> np.ndarray:
    """Unit reference step: the state is (x, integral of e); u = KP e + KI integral, e = 1 - y."""
    pieces = []

    def u_at(s: float, k: int) -> float:  # the command at time s, which lies in interval k (before 0: none)
        if k < 0:
            return 0.0
        x, z = pieces[k](s)
        return KP * (1.0 - (u_at(s - TAU, k - 1) + x)) + KI * z

    state = np.zeros(2)
    for k in range(round(T_END / TAU)):
        def rhs(t, s, k=k):
            late = u_at(t - TAU, k - 1)
            return [-s[0] + late, 1.0 - (late + s[0])]
        sol = solve_ivp(rhs, (k * TAU, (k + 1) * TAU), state, rtol=1e-10, atol=1e-12, dense_output=True)
        pieces.append(sol.sol)
        state = sol.y[:, -1]
    out = np.empty(t_out.size)
    for j, t in enumerate(t_out):
        k = min(int(np.floor(t / TAU)), len(pieces) - 1)
        out[j] = u_at(t - TAU, k - 1) + pieces[k](t)[0]
    return out


def test_a_biproper_delayed_step_reports_the_error_it_has():
    run = linear_step(Loop(Plant.from_string("(s+2)/(s+1)", delay=TAU), Controller("PI", {"kp": KP, "ki": KI})),
                      T_END, 801)
    off_jumps = np.abs(run.t / TAU - np.round(run.t / TAU)) > 1e-6  # the reference is right-continuous: compare
    ref = _reference(run.t[off_jumps])
    actual = np.abs(run.y[off_jumps] - ref)
    assert actual.max() < 1e-4
    assert float(np.max(run.error)) < 1e-3  # was 0.062
    assert np.all(actual <= run.error[off_jumps] + 2e-6)  # the reported bound holds (to the reference's tolerance)
    assert run.y[-1] == pytest.approx(1.0, abs=1e-3)
