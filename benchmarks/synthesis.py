"""Synthesis speed: certified PID design by synth against scipy differential evolution, and scaling.

The problem: the X-4 rotor plant of seed 1 (eq. 5) with a 10 ms in-loop delay, a PID controller with a
fixed derivative filter (tf = 2 ms; kp, ki, kd free), four requirements (|S| <= -15 dB below 5 rad/s,
peak |S| <= 6 dB, peak |T| <= 2 dB, the slew-rate Bode bound with B = 10000 PWM/s and Delta_e = 5 rad/s
up to 1000 rad/s) and the objective "maximize the integral gain ki".

- synth: ``synth.synthesis.multi.design_convex`` with a 500-point design grid (convex-concave iterations
  with cvxpy + Clarabel; the NLP polish with casadi + IPOPT where it may improve the answer, skipped
  when the convex answer is a KKT point of the polish's own problem; then the certificate: every
  requirement on a grid at least 20x denser with refined peaks, and exact closed-loop stability with the
  delay). Its time is the median of three designs; a second row runs the polish anyway.
- baseline: ``scipy.optimize.differential_evolution`` on the penalty form of the same problem, the same
  500 frequencies, closed-loop stability decided by synth's exact test; its answer is then put through
  the same certificate (``synth.check`` at the density synth's certificate used).

Then the scaling of synth's certified design time with the design-grid size (100 ... 10,000 points)
and with the number of plants (1 ... 20 gain variants between 0.85x and 1.1x).

Run: ``python benchmarks/synthesis.py`` (about 2 minutes; ``--quick`` for a smaller scaling table).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.optimize import differential_evolution

from synth.check import check
from synth.controllers import Controller
from synth.loop import Loop
from synth.results import DesignResult
from synth.spec import parse_spec
from synth.stability import closed_loop_stability
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.multi import design_convex

SPEC = """
name: pid_benchmark
plant:
  tf: "23*(s+0.43)/((s+9.6)*(s+0.54))"
  delay: 0.01
{variants}
controller: {{type: PID, bounds: {{kp: [0, 20], ki: [0, 2000], kd: [0, 0.5], tf: [0.002, 0.002]}}}}
requirements:
  - {{type: sensitivity, max_db: -15, band: [0, 5]}}
  - {{type: peak_sensitivity, max_db: 6}}
  - {{type: peak_complementary, max_db: 2}}
  - {{type: slew_rate, rate_limit: 10000, max_error: 5, band: [0.1, 1000]}}
objective: {{maximize: integral_gain}}
"""


def make_spec(n_plants: int = 1):
    """The benchmark spec with ``n_plants`` plants (the nominal one and gain variants 0.85x ... 1.1x)."""
    if n_plants <= 1:
        return parse_spec(SPEC.format(variants=""))
    gains = [g for g in np.linspace(0.85, 1.1, n_plants) if abs(g - 1.0) > 1e-9][: n_plants - 1]
    lines = "  variants:\n" + "".join(f"    - {{label: g{i}, gain: {g:.6f}}}\n" for i, g in enumerate(gains))
    return parse_spec(SPEC.format(variants=lines.rstrip("\n")))


def penalty_problem(spec, n_points: int):
    """Penalty objective of the spec on ``n_points`` log-spaced frequencies (the baseline's problem)."""
    w = np.logspace(-2, 4, n_points)
    plant = spec.plant.build()
    G = plant.freqresp(w)
    in_band = w <= 5.0
    slew_band = (w >= 0.1) & (w <= 1000.0)
    s_low, s_peak, t_peak = 10 ** (-15 / 20), 10 ** (6 / 20), 10 ** (2 / 20)
    B, de = 10000.0, 5.0
    evaluations = [0]

    def controller(x):
        return Controller("PID", {"kp": x[0], "ki": x[1], "kd": x[2], "tf": 0.002})

    def penalty(x):
        evaluations[0] += 1
        C = x[0] + x[1] / (1j * w) + x[2] * 1j * w / (0.002j * w + 1.0)
        L = C * G
        S = 1.0 / (1.0 + L)
        T = L * S
        viol = [np.max(np.abs(S[in_band])) / s_low - 1.0, np.max(np.abs(S)) / s_peak - 1.0,
                np.max(np.abs(T)) / t_peak - 1.0, np.max(de * np.abs(C[slew_band]) * w[slew_band]) / B - 1.0]
        total = sum(max(0.0, v) for v in viol)
        loop = Loop(plant, controller(x))
        if not closed_loop_stability(loop.num, loop.den, plant.delay).stable:
            total += 1.0
        return -x[1] + 1e4 * total

    return penalty, controller, evaluations


def run_synth(spec, n_points: int, nlp: bool | str = True) -> tuple[float, float | None, bool, DesignResult]:
    t0 = time.perf_counter()
    result = design_convex(spec, ConvexSettings(n_points=n_points), nlp=nlp)
    elapsed = time.perf_counter() - t0
    ki = result.controller.parameters["ki"] if result.controller is not None else None
    return elapsed, ki, bool(result.feasible), result


def run_baseline(spec, n_points: int, seed: int, maxiter: int,
                 per_decade: int = 1600) -> tuple[float, float, bool, Controller, int]:
    penalty, controller, evaluations = penalty_problem(spec, n_points)
    t0 = time.perf_counter()
    res = differential_evolution(penalty, [(0, 20), (0, 2000), (0, 0.5)], seed=seed, maxiter=maxiter, tol=1e-8,
                                 polish=True)
    elapsed = time.perf_counter() - t0
    ctrl = controller(res.x)
    certified = check(spec, ctrl, per_decade=per_decade).feasible
    return elapsed, float(res.x[1]), certified, ctrl, evaluations[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=3, help="differential-evolution seeds")
    ap.add_argument("--maxiter", type=int, default=300, help="differential-evolution generations")
    ap.add_argument("--quick", action="store_true", help="smaller scaling table")
    args = ap.parse_args()

    spec = make_spec(1)
    design_convex(spec, ConvexSettings(n_points=100))  # warm-up: imports, solver set-up
    runs = [run_synth(spec, 500) for _ in range(3)]
    t_synth = float(np.median([r[0] for r in runs]))
    _, ki_synth, ok_synth, result = runs[0]
    per_decade = result.certificate.per_decade
    print("PID design, 500 frequency points, 4 requirements, maximize ki [PWM/(rad/s)/s]\n")
    print(f"{'method':<46} {'time [s]':>9} {'ki':>9} {'certified':>9} {'evals':>7}")
    print(f"{'synth (convex-concave, certificate), median of 3':<46} {t_synth:9.3f} {ki_synth:9.3f} "
          f"{ok_synth!s:>9} {'':>7}   ({', '.join(f'{r[0]:.3f}' for r in runs)} s)")
    forced = [run_synth(spec, 500, nlp="always") for _ in range(3)]
    t_forced = float(np.median([r[0] for r in forced]))
    print(f"{'synth with the NLP polish run anyway, median':<46} {t_forced:9.3f} {forced[0][1]:9.3f} "
          f"{forced[0][2]!s:>9} {'':>7}   ({', '.join(f'{r[0]:.3f}' for r in forced)} s)")
    rows = []
    for seed in range(args.seeds):
        t, ki, ok, _, n = run_baseline(spec, 500, seed, args.maxiter, per_decade)
        rows.append((t, ki, ok))
        print(f"{'differential_evolution (penalty), seed ' + str(seed):<46} {t:9.2f} {ki:9.3f} {ok!s:>9} {n:>7}")
    # the same penalty on the certificate's density (1600 points per decade over the 6 decades): what it costs
    # differential evolution to return an answer that the dense certificate can accept
    t, ki, ok, _, n = run_baseline(spec, 9600, 0, args.maxiter, per_decade)
    print(f"{'differential_evolution on the certificate grid':<46} {t:9.2f} {ki:9.3f} {ok!s:>9} {n:>7}")
    t_de = float(np.median([r[0] for r in rows]))
    best_de = max((r[1] for r in rows if r[2]), default=float("nan"))
    print(f"\nsynth: {result.controller}\n  {result.method}")
    if np.isnan(best_de):
        verdict = "no differential-evolution answer passes the certificate; synth's does"
    else:
        verdict = "at least as good" if ki_synth >= best_de * (1 - 1e-4) else "WORSE"
        verdict = f"synth ki {ki_synth:.3f} vs best certified DE ki {best_de:.3f}: {verdict}"
    print(f"speed-up (median DE time / synth time): {t_de / t_synth:.1f}x ({t_de / t_forced:.1f}x with the polish "
          f"run anyway); {verdict}")

    print("\nScaling: certified design time against design-grid size (1 plant)\n")
    print(f"{'points':>7} {'time [s]':>9} {'ki':>9} {'certified':>9} {'solves':>7} {'cert/dec':>9}")
    for n in ([100, 1000, 3000] if args.quick else [100, 300, 1000, 3000, 10000]):
        t, ki, ok, r = run_synth(spec, n)
        print(f"{n:>7} {t:9.2f} {ki:9.3f} {ok!s:>9} {_solves(r):>7} {r.certificate.per_decade:>9}")
    print("\nScaling: certified design time against the number of plants (500 points)\n")
    print(f"{'plants':>7} {'time [s]':>9} {'ki':>9} {'certified':>9} {'solves':>7} {'cert/dec':>9}")
    for m in ([1, 5, 20] if args.quick else [1, 2, 5, 10, 20]):
        t, ki, ok, r = run_synth(make_spec(m), 500)
        print(f"{m:>7} {t:9.2f} {ki:9.3f} {ok!s:>9} {_solves(r):>7} {r.certificate.per_decade:>9}")


def _solves(result: DesignResult) -> int:
    return sum(c["convex_solves"] for c in result.extras["synthesis"]["convex"])


if __name__ == "__main__":
    main()
