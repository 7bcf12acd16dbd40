"""Randomized test of the start-state handling of whole-record fits (session 46).

``identify`` fits a record assuming the plant was at rest at its first input sample; since session 46 every
whole-record fit tests that assumption (a score test, ``solver["start_state"]``) and, where the start state matters,
refits with the first samples weighted 0 (``whole_record_note`` says "does not start at rest").

The records here come from a seeded generator and a reference simulation of this file's own: the truth is built
as a transfer function in the structure's own parameterization, turned into a state-space model by
``scipy.signal.tf2ss``, discretized with a zero-order hold (``cont2discrete(method="zoh")``, the input is a
held command) and simulated by ``scipy.signal.dlsim`` from an initial state chosen here; nothing of synth's own
simulation is used. Each case is drawn from ``(SEED, start, index)``: plant order 1-3 (a real pole, two real poles
and a real zero, a lightly damped pair with damping 0.05-0.5, a real pole with such a pair, with or without a real
zero, three real poles), a delay of 0-5 samples (fitted or fixed), sample time 1-10 ms, 3,000-20,000 samples, a
random staircase or low-passed noise as input, white output noise of 0.5-5 % of the output's std, an output offset.
The slowest mode's time constant is 1/25-1/40 of the record, so that a start-up transient (scaled to 30-1000 noise
std) dies out within a third of it.

Two starts:

* settled: the initial state is the steady state for the constant input ``u[0]`` (what the fit assumes): the
  start state must not matter, nothing is left out and every parameter is within 4.5 std of the truth;
* cut: the record is cut out of a longer one, a fraction of a time constant after a step, so that both the state and
  the input are in progress; the free response of that start (scaled up where needed to at least 30 noise std) must
  be detected and left out, after which every parameter is within 5 std of the truth, while a plain whole-record fit
  (``fit_structure``, no start handling) is off by more than 5 std on at least half of these records.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.errors import FitError
from synth.ident.identification import identify
from synth.ident.timefit import fit_structure

SEED = 20461

STRUCTURES = {
    "first": "k/(s+p)",
    "pair": "k*w^2/(s^2+2*z*w*s+w^2)",
    "zero2": "k*(s+z)/((s+p1)*(s+p2))",
    "pair3": "k*w^2/((s+p)*(s^2+2*z*w*s+w^2))",
    "zpair3": "k*(s+a)/((s+p)*(s^2+2*z*w*s+w^2))",
    "real3": "k/((s+p1)*(s+p2)*(s+p3))",
}
KINDS = list(STRUCTURES)
# names a fit may exchange (p1, p2, p3 of a product of real poles are the same plant in any order)
EXCHANGEABLE = ("p1", "p2", "p3")
# names whose joint change of sign leaves the plant unchanged: compared by absolute value
SIGN_PAIR = ("w", "z")

START_KEYS = {"statistic", "threshold", "dof", "shift", "shifted", "window", "first", "matters"}
AT_REST = "does not start at rest"


@dataclass(frozen=True)
class Case:
    kind: str
    structure: str
    truth: dict[str, float]
    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    dt: float
    samples_delay: int
    delay: str | float | None
    sigma: float
    tau: float
    free: np.ndarray  # the start state's free response in y (zero when settled), noise-free

    @property
    def duration(self) -> float:
        return float(self.t.size * self.dt)

    def describe(self) -> str:
        truth = ", ".join(f"{k}={v:.6g}" for k, v in self.truth.items())
        return (f"{self.structure} [{truth}], delay {self.samples_delay} samples ({self.delay!r}), "
                f"{self.t.size} samples of {self.dt * 1e3:.3f} ms, noise std {self.sigma:.3g}, tau {self.tau:.3g} s")


def _coefficients(kind: str, th: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of the truth, written out here (not by synth's structure parser)."""
    k = th["k"]
    if kind == "first":
        return np.array([k]), np.array([1.0, th["p"]])
    if kind == "zero2":
        return np.array([k, k * th["z"]]), np.polymul([1.0, th["p1"]], [1.0, th["p2"]])
    if kind == "real3":
        return np.array([k]), np.polymul(np.polymul([1.0, th["p1"]], [1.0, th["p2"]]), [1.0, th["p3"]])
    w, z = th["w"], th["z"]
    pair = np.array([1.0, 2.0 * z * w, w * w])
    if kind == "pair":
        return np.array([k * w * w]), pair
    if kind == "pair3":
        return np.array([k * w * w]), np.polymul([1.0, th["p"]], pair)
    if kind == "zpair3":
        return np.array([k, k * th["a"]]), np.polymul([1.0, th["p"]], pair)
    raise AssertionError(kind)


def _draw_plant(rng: np.random.Generator, kind: str, tau: float) -> dict[str, float]:
    """Parameters, named as the structure names them, whose slowest mode decays with time constant ``tau``."""
    lam = 1.0 / tau
    if kind == "first":
        return {"k": lam * rng.uniform(0.5, 3.0) * rng.choice([-1.0, 1.0]), "p": lam}
    if kind == "zero2":
        p1, p2 = lam, lam * rng.uniform(2.5, 8.0)
        z = lam * rng.choice([rng.uniform(0.3, 0.6), rng.uniform(1.6, 2.2), rng.uniform(10.0, 20.0)])
        return {"k": p1 * p2 / z * rng.uniform(0.5, 3.0), "z": z, "p1": p1, "p2": p2}
    if kind == "real3":
        p2 = lam * rng.uniform(2.0, 4.0)
        p3 = p2 * rng.uniform(2.0, 4.0)
        return {"k": lam * p2 * p3 * rng.uniform(0.5, 3.0), "p1": lam, "p2": p2, "p3": p3}
    z = rng.uniform(0.05, 0.5)  # the pair decays with z*w
    if kind == "pair":
        return {"k": rng.uniform(0.5, 3.0), "w": lam / z, "z": z}
    if kind == "pair3":
        if rng.random() < 0.5:  # the real pole slowest, the pair up to 4 times faster
            return {"k": rng.uniform(0.5, 3.0), "w": lam / z * rng.uniform(1.5, 4.0), "p": lam, "z": z}
        return {"k": rng.uniform(0.5, 3.0), "w": lam / z, "p": lam * rng.uniform(2.5, 8.0), "z": z}
    if kind == "zpair3":
        p = lam * rng.uniform(2.5, 8.0)
        a = p * rng.uniform(0.2, 0.5)
        return {"k": p / a * rng.uniform(0.5, 3.0), "a": a, "p": p, "z": z, "w": lam / z}
    raise AssertionError(kind)


def _draw_input(rng: np.random.Generator, n: int, dt: float, tau: float, fastest: float, style: str) -> np.ndarray:
    if style == "stairs":  # levels held for exponentially distributed times (at most 3 means)
        mean_hold = rng.uniform(0.5, 2.0) * tau
        u = np.empty(n)
        i = 0
        while i < n:
            hold = int(min(rng.exponential(mean_hold), 3.0 * mean_hold) / dt) + 1
            u[i:i + hold] = rng.normal()
            i += hold
    else:  # white noise through a 2nd-order Butterworth beyond the plant's fastest pole
        fc = min(rng.uniform(1.0, 3.0) * fastest / (2.0 * np.pi), 0.2 / dt)
        b, a = signal.butter(2, fc, fs=1.0 / dt)
        u = signal.lfilter(b, a, rng.normal(size=n + 2000))[2000:]
        u = u / np.std(u)
    return u + rng.uniform(-2.0, 2.0)


@functools.cache
def make_case(start: str, index: int) -> Case:
    """The record of case ``index``: deterministic in (SEED, start, index)."""
    rng = np.random.default_rng([SEED, ["settled", "cut"].index(start), index])
    kind = KINDS[index % len(KINDS)]
    n = int(rng.integers(3000, 20001))
    dt = float(rng.uniform(0.001, 0.010))
    tau = n * dt / rng.uniform(25.0, 40.0)
    truth = {k: float(v) for k, v in _draw_plant(rng, kind, tau).items()}
    num, den = _coefficients(kind, truth)
    assert np.all(np.roots(den).real < 0)
    fastest = float(np.max(np.abs(np.roots(den))))
    d = int(rng.choice([0, 0, 1, 2, 3, 5]))
    style = str(rng.choice(["stairs", "noise"]))
    # the cut: 1-3 time constants into a longer record, for a staircase a fraction of a time constant after its
    # last step before there (or its first step, if it has none yet): the state is then in motion, and the input
    # at a level the plant has not settled at
    n_pre = int(rng.uniform(1.0, 3.0) * tau / dt) if start == "cut" else 0
    spare = int(8.0 * tau / dt) if start == "cut" else 0  # a staircase holds a level for at most 6 tau
    u_all = _draw_input(rng, n_pre + spare + n, dt, tau, fastest, style)
    if start == "cut" and style == "stairs":
        steps = np.flatnonzero(np.diff(u_all[:n_pre + spare]) != 0) + 1
        step = steps[steps <= n_pre][-1] if np.any(steps <= n_pre) else steps[0]
        n_pre = int(step + rng.uniform(0.05, 0.5) * tau / dt)
    u_all = u_all[:n_pre + n]
    u = u_all[n_pre:]

    ad, bd, cd, dd, _ = signal.cont2discrete(signal.tf2ss(num, den), dt, method="zoh")

    def simulate(u_in: np.ndarray, u_before: float) -> np.ndarray:
        """Response to ``u_in`` delayed by d samples, from the steady state at ``u_before`` (held before)."""
        delayed = np.concatenate([np.full(d, u_before), u_in[:u_in.size - d]])
        x0 = np.linalg.solve(np.eye(ad.shape[0]) - ad, bd[:, 0] * u_before)
        return signal.dlsim((ad, bd, cd, dd, dt), delayed[:, None], x0=x0)[1][:, 0]

    y_rest = simulate(u, u[0])  # what the fit assumes: settled at u[0]
    sigma = rng.uniform(0.005, 0.05) * float(np.std(y_rest))
    free = np.zeros(n)
    if start == "cut":
        free = simulate(u_all, u_all[0])[n_pre:] - y_rest  # the cut state's (and delay line's) free response
        amplitude = float(np.max(np.abs(free)))
        assert amplitude > 1e-3 * np.std(y_rest)  # a state in motion, not rounding
        # scaled into 30-1000 noise std: clearly there, and gone within a third of the record
        free = free * float(np.clip(amplitude / sigma, 30.0, 1000.0)) * sigma / amplitude
    y = y_rest + free + rng.uniform(-5.0, 5.0) + sigma * rng.normal(size=n)
    if d > 0:
        delay = "fit" if rng.random() < 0.6 else d * dt
    else:
        delay = None  # (a fitted delay whose truth is 0 takes 20-60 s per fit: left out for time)
    return Case(kind, STRUCTURES[kind], truth, np.arange(n) * dt, u, y, dt, d, delay, sigma, tau, free)


def zscores(case: Case, parameters: dict[str, float], std: dict[str, float]) -> dict[str, float]:
    """(fit - truth) / std per parameter: exchangeable poles matched in sorted order, (w, z) by absolute value,
    the delay where it was fitted; inf where the std is not a finite positive number (an unidentified parameter
    is not within any number of std)."""

    def z(value: float, true: float, s: float) -> float:
        return (value - true) / s if np.isfinite(s) and s > 0 else np.inf

    out = {}
    poles = [k for k in EXCHANGEABLE if k in case.truth]
    fitted = sorted(poles, key=lambda k: parameters[k])
    for name, true in zip(fitted, sorted(case.truth[k] for k in poles)):
        out[name] = z(parameters[name], true, std[name])
    for name, true in case.truth.items():
        if name not in poles:
            value = abs(parameters[name]) if name in SIGN_PAIR else parameters[name]
            out[name] = z(value, true, std[name])
    if case.delay == "fit":
        out["delay"] = z(parameters["delay"], case.samples_delay * case.dt, std["delay"])
    return out


@functools.cache
def identified(start: str, index: int):
    case = make_case(start, index)
    try:
        return identify((case.t, case.u, case.y), case.structure, delay=case.delay, average="none",
                        compare_directions=False)
    except FitError as err:
        return err


@functools.cache
def plain_fit(index: int):
    case = make_case("cut", index)
    return fit_structure(record_from_arrays(case.t, case.u, case.y), case.structure, case.delay)


SETTLED = list(range(8))
# the first nine cut records, and 29 (three real poles: before the fix below, 5 and 29 came back with coinciding
# poles and infinite std, nothing left out)
CUT = [0, 1, 2, 3, 4, 5, 6, 7, 8, 29]
# A cut record whose first whole-record fit ends in a wrong minimum leaves residuals far from white everywhere; the
# start-state test's threshold, scaled up by them, then missed the start, and identify returned the wrong fit without
# a note (5, 29, 45 as found). Since then such a "masked" start is judged by a refit without it, from the fit's own
# parameters and from the deterministic start. 45 still ends in a FitError (the refits stay in the wrong basin):
# a failure, no longer a wrong result, but not the fit this test asks for. (Of the first 48 cut records, the 40
# without three real poles failed in 3 as found: 45, 32 (the same, slower) and 38 (FitError, IPOPT's iteration
# limit, after 2 minutes); three real poles failed in each of the 5 tried: 5, 29, 17 (FitError: start state "still
# moves k by 30.7 std" with 58 of 85 s left out, where the true free response is below the noise after 9 s), 11 and
# 23 (more than 150 s each).)
KNOWN_FAILING_CUT = {
    45: "k*w^2/((s+p)*(s^2+2*z*w*s+w^2)): a FitError after 4 refits (they stay in the fit's wrong basin); before, "
        "k -0.60 (truth 1.71), w 0.22 (2.57): 2370 std, nothing left out",
}
# settled records: at most this many with a parameter beyond 4.5 std. The start-state test's level is 0.001 per
# case, which makes `matters` a hard per-case assertion; a parameter 4.5 std off has a probability of ~7e-6 per
# parameter for a Gaussian estimate, but the reported std is a linearization and the records are finite, so one
# exception in the sample is tolerated (the per-case bound is 6 std).
SETTLED_EXCEPTIONS = 1
# cut records on which identify may raise FitError: none. The generator makes the free response die out within a
# third of the record (checked below), well inside the 75 % that may be left out.
CUT_FIT_ERRORS = 0

pytestmark = pytest.mark.xdist_group("start_state_random")  # one worker: the cached fits are shared


@pytest.mark.parametrize("index", SETTLED)
def test_settled_record_is_fitted_whole(index: int) -> None:
    case = make_case("settled", index)
    res = identified("settled", index)
    assert not isinstance(res, FitError), f"{case.describe()}: {res}"
    state = res.fit.solver["start_state"]
    assert START_KEYS <= set(state), state
    assert not state["matters"], (case.describe(), state)
    assert state["first"] == 0.0, (case.describe(), state)
    assert AT_REST not in res.whole_record_note, (case.describe(), res.whole_record_note)
    assert res.fit.weights is None or np.all(res.fit.weights > 0), case.describe()
    z = zscores(case, res.fit.parameters, res.fit.std)
    assert max(abs(v) for v in z.values()) <= 6.0, (case.describe(), res.fit.parameters, res.fit.std, z)


def test_settled_parameters_within_4_5_std() -> None:
    off = {}
    for index in SETTLED:
        res = identified("settled", index)
        if isinstance(res, FitError):
            off[index] = str(res)
            continue
        z = zscores(make_case("settled", index), res.fit.parameters, res.fit.std)
        if max(abs(v) for v in z.values()) > 4.5:
            off[index] = z
    assert len(off) <= SETTLED_EXCEPTIONS, off


@pytest.mark.parametrize("index", CUT + [pytest.param(i, marks=pytest.mark.xfail(strict=True, reason=why))
                                         for i, why in KNOWN_FAILING_CUT.items()])
def test_cut_record_is_fitted_after_its_start(index: int) -> None:
    case = make_case("cut", index)
    # the generator: a start-up transient of at least 30 noise std, gone below one noise std within a third of
    # the record (so leaving it out is always possible)
    assert np.max(np.abs(case.free)) >= 29.9 * case.sigma
    assert case.t[np.flatnonzero(np.abs(case.free) > case.sigma)[-1]] < case.duration / 3
    res = identified("cut", index)
    assert not isinstance(res, FitError), f"{case.describe()}: {res}"
    state = res.fit.solver["start_state"]
    assert START_KEYS <= set(state), state
    assert AT_REST in res.whole_record_note, (case.describe(), state, res.whole_record_note)
    first = state["first"]
    assert 0.0 < first <= 0.75 * case.duration + case.dt, (case.describe(), state)
    # the samples before `first` are weighted 0, those after it 1
    assert res.fit.weights is not None
    assert np.all(res.fit.weights[case.t < first - 0.5 * case.dt] == 0), (case.describe(), state)
    assert np.all(res.fit.weights[case.t > first + 0.5 * case.dt] > 0), (case.describe(), state)
    assert not state["matters"], (case.describe(), state)  # left in, it would have raised FitError
    z = zscores(case, res.fit.parameters, res.fit.std)
    assert max(abs(v) for v in z.values()) <= 5.0, (case.describe(), res.fit.parameters, res.fit.std, state, z)


def test_cut_records_fit_errors() -> None:
    errors = {i: str(res) for i in CUT if isinstance(res := identified("cut", i), FitError)}
    assert len(errors) <= CUT_FIT_ERRORS, errors


def test_plain_fit_of_cut_records_is_biased() -> None:
    """Without the start handling the same records give some parameter more than 5 std off in at least half of
    the cut cases: the handling is what makes the previous test pass."""
    worst = {}
    for index in CUT:
        fit = plain_fit(index)
        worst[index] = max(abs(v) for v in zscores(make_case("cut", index), fit.parameters, fit.std).values())
    biased = [i for i, z in worst.items() if not z <= 5.0]  # (nan or inf std: not a fit within 5 std either)
    assert 2 * len(biased) >= len(CUT), worst


def test_a_cut_record_the_refits_cannot_mend_is_a_failure_not_a_wrong_fit() -> None:
    """45 (see KNOWN_FAILING_CUT): identify must not return the fit 2370 std off; it fails, naming the start."""
    res = identified("cut", 45)
    assert isinstance(res, FitError) and AT_REST in str(res), res
