"""Harmonic balance on random loops against a plain reference written here: every grid frequency's amplitude
solved to full precision by bisection in log A, every sign change of the phase balance refined by bisection.
:func:`synth.sim.describing.harmonic_balance` locates the sign changes with coarse amplitudes (each from its
neighbour's) before refining; it must find the same cycles."""

from __future__ import annotations

import numpy as np
import pytest

from synth.sim.describing import harmonic_balance, rate_limiter_df, saturation_df

GRID_POINTS = 60
A_RANGE = (1e-2, 1e4)


def _bisect(f, lo: float, hi: float, steps: int = 80) -> float:
    f_lo = f(lo)
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):  # adjacent floats: the remaining steps would not move either end (same result, cheaper)
            break
        f_mid = f(mid)
        if np.sign(f_mid) == np.sign(f_lo):
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _reference(L, N, w_range):
    lo, hi = np.log(A_RANGE[0]), np.log(A_RANGE[1])

    def amplitude(w):
        target = 1.0 / abs(L(np.array([w]))[0])
        g = lambda u: abs(N(np.exp(u), w)) - target  # noqa: E731
        if g(lo) < 0 or g(hi) > 0:
            return None
        return float(np.exp(_bisect(g, lo, hi)))

    def phase(w):
        a = amplitude(w)
        return None if a is None else float(np.angle(-L(np.array([w]))[0] * N(a, w)))

    ws = np.geomspace(*w_range, GRID_POINTS)
    r = [phase(w) for w in ws]
    out = []
    for i in range(GRID_POINTS - 1):
        if r[i] is None or r[i + 1] is None or np.sign(r[i]) == np.sign(r[i + 1]) or abs(r[i] - r[i + 1]) > np.pi:
            continue
        w = float(np.exp(_bisect(lambda v: phase(np.exp(v)) or 0.0, np.log(ws[i]), np.log(ws[i + 1]))))
        out.append((w, amplitude(w)))
    return out


def _loop(rng):
    poles = np.exp(rng.uniform(np.log(0.3), np.log(30.0), 3))
    k = float(np.prod(poles) * np.exp(rng.uniform(np.log(2.0), np.log(60.0))))
    tau = float(rng.choice([0.0, rng.uniform(0.001, 0.1)]))

    def L(w):
        s = 1j * np.asarray(w, float)
        return k * np.exp(-s * tau) / np.prod([s + p for p in poles], axis=0)

    limit, rate = float(rng.uniform(0.5, 5.0)), float(np.exp(rng.uniform(np.log(1.0), np.log(200.0))))

    def N(a, w):
        return complex(saturation_df(a, limit)) * rate_limiter_df(a, w, rate)

    return L, N, (0.05 * float(poles.min()), 20.0 * float(poles.max()))


@pytest.mark.parametrize("seed", range(3))
def test_harmonic_balance_finds_the_reference_cycles(seed):
    rng = np.random.default_rng(1000 + seed)
    with_cycles = 0
    for _ in range(10):
        L, N, w_range = _loop(rng)
        ref = _reference(L, N, w_range)
        got = harmonic_balance(L, N, w_range, A_RANGE, GRID_POINTS)
        assert len(got) == len(ref), (ref, got)
        for c, (w, a) in zip(got, ref):
            assert c.frequency == pytest.approx(w, rel=1e-7)
            assert c.amplitude == pytest.approx(a, rel=1e-6)
        with_cycles += bool(ref)
    assert with_cycles >= 3  # the draw is not all cycle-free loops
