"""Speed of the sampled nonlinear simulation against baselines measured in the same run.

Case: the X-4 rotor loop of seed 1 (eq. 5 plant, P(3), rate limit 10000 PWM/s, 0-255 PWM
saturation, 400 Hz sample-and-hold and 1.2 rad/s quantizer on the speed sensor), 10 s at 1 kHz
(10001 steps), 820 -> 920 rad/s step.

Baselines:
  * python-control ``forced_response`` of the same sampled loop with every nonlinear block off
    (linear: the nonlinear loop cannot be expressed in python-control);
  * a plain per-step Python loop (numpy for the state update) hand-written for this one loop;
  * synth's own general kernel run as plain Python (``NUMBA_DISABLE_JIT=1``), fresh process.

Goal (issue 5): 10 s of 1 kHz closed loop in under 0.5 s. Also timed: a batch of 100 gain
variants at once, and the first call in a fresh process (numba loads its on-disk cache, or
compiles on the very first run).

Run:  python benchmarks/sim_speed.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from synth.controllers import Controller  # noqa: E402
from synth.plant import Plant  # noqa: E402
from synth.sim.blocks import Quantizer, RateLimit, SampleHold, Saturation  # noqa: E402
from synth.sim.discretize import delayed_zoh, tf_to_ss  # noqa: E402
from synth.sim.loops import NonlinearLoop, OperatingPoint  # noqa: E402
from synth.sim.signals import step_reference  # noqa: E402
from synth.sim.simulator import simulate, simulate_batch  # noqa: E402

PLANT = "23*(s+0.43)/((s+9.6)*(s+0.54))"
T_END, DT = 10.0, 0.001


def x4_loop(kp: float = 3.0) -> NonlinearLoop:
    """The benchmark loop."""
    return NonlinearLoop(Plant.from_string(PLANT), Controller("P", {"kp": kp}),
                         actuator=[RateLimit(10000), Saturation(0, 255)], sensor=[SampleHold(400), Quantizer(1.2)],
                         operating_point=OperatingPoint(200, 870), dt=DT)


def naive_python_loop(kp: float = 3.0) -> np.ndarray:
    """The same nonlinear loop stepped in plain Python (numpy state update)."""
    G = Plant.from_string(PLANT)
    A, B, C, _ = tf_to_ss(G.num, G.den)
    d = delayed_zoh(A, B, DT, 0.0)
    Ad, Bd = d.Ad, d.B_late
    n = round(T_END / DT) + 1
    y_rest = 870 + kp * G.dc_gain() * (820 - 870) / (1 + kp * G.dc_gain())
    x = np.linalg.solve(np.eye(2) - Ad, Bd * ((y_rest - 870) / G.dc_gain()))
    u_prev = 200 + kp * (820 - y_rest)
    held, next_sample = y_rest, 0.0
    out = np.empty(n)
    for k in range(n):
        y = 870 + C @ x
        if k >= next_sample - 1e-9:
            held = y
            next_sample += 2.5
        meas = 1.2 * np.floor(held / 1.2 + 0.5)
        u = 200 + kp * (920 - meas)
        u = min(max(u, u_prev - 10.0), u_prev + 10.0)
        u = min(max(u, 0.0), 255.0)
        u_prev = u
        x = Ad @ x + Bd * (u - 200)
        out[k] = y
    return out


def python_control_linear() -> np.ndarray:
    """python-control forced_response of the sampled linear loop (10001 steps)."""
    import control

    G = control.tf(*[list(p) for p in (Plant.from_string(PLANT).num, Plant.from_string(PLANT).den)])
    T = control.feedback(3.0 * control.c2d(G, DT, "zoh"), 1)
    t = np.arange(round(T_END / DT) + 1) * DT
    return np.asarray(control.forced_response(T, t, np.full(t.size, 50.0)).outputs)


def timed(fn, repeat: int) -> list[float]:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    ref = step_reference(820, 920)
    loop = x4_loop()
    fresh = [sys.executable, "-c", f"import sys; sys.path.insert(0, {str(ROOT)!r})\n"
             + "from benchmarks.sim_speed import x4_loop\nfrom synth.sim.signals import step_reference\n"
             "from synth.sim.simulator import simulate\nimport time\nloop = x4_loop()\n"
             "t0 = time.perf_counter()\nsimulate(loop, step_reference(820, 920), 10.0)\n"
             "print(time.perf_counter() - t0)"]
    first = float(subprocess.run(fresh, cwd=ROOT, check=True, capture_output=True, text=True).stdout.split()[-1])
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    no_jit = [float(subprocess.run(fresh, cwd=ROOT, check=True, capture_output=True, text=True, env=env)
                    .stdout.split()[-1]) for _ in range(2)]
    batch_code = fresh[2].replace(
        "simulate(loop, step_reference(820, 920), 10.0)",
        "import numpy as np\nfrom synth.sim.simulator import simulate_batch\n"
        "simulate_batch([x4_loop(k) for k in np.linspace(1, 10, 100)], step_reference(820, 920), 10.0)")
    batch_script = [*fresh[:2], batch_code]
    batch_no_jit = [float(subprocess.run(batch_script, cwd=ROOT, check=True, capture_output=True, text=True,
                                         env=env).stdout.split()[-1])]
    simulate(loop, ref, T_END)  # warm: compiled code loaded
    a = simulate(loop, ref, T_END).output
    b = naive_python_loop()
    agree = float(np.max(np.abs(a - b)))
    loops100 = [x4_loop(k) for k in np.linspace(1, 10, 100)]
    rows = [
        ("synth simulate, nonlinear X-4 loop, 10 s @ 1 kHz",
         timed(lambda: simulate(loop, ref, T_END), args.repeat)),
        ("python-control forced_response, linear loop (baseline)",
         timed(python_control_linear, max(3, args.repeat // 2))),
        ("plain Python per-step loop, nonlinear, hand-specialized (baseline)", timed(naive_python_loop, 3)),
        ("synth's general kernel run as plain Python (NUMBA_DISABLE_JIT=1)", no_jit),
        ("synth simulate_batch, 100 gain variants x 10 s", timed(lambda: simulate_batch(loops100, ref, T_END), 3)),
        ("the same batch run as plain Python (NUMBA_DISABLE_JIT=1)", batch_no_jit),
    ]
    print(f"{'case':68s} {'median [s]':>10s} {'min [s]':>8s} {'max [s]':>8s}")
    for name, ts in rows:
        print(f"{name:68s} {statistics.median(ts):10.4f} {min(ts):8.4f} {max(ts):8.4f}")
    print(f"{'first call in a fresh process (loads the compiled code from disk)':68s} {first:10.4f}")
    med = statistics.median(rows[0][1])
    print(f"\nplain-Python loop and synth agree to {agree:.2e} rad/s (same equations)")
    print(f"batch: {statistics.median(rows[4][1]) / 100 * 1000:.2f} ms per 10 s variant")
    verdict = "MET" if med < 0.5 else "NOT MET"
    print(f"goal: 10 s of 1 kHz closed loop under 0.5 s -> {verdict} ({med:.4f} s median)")


if __name__ == "__main__":
    main()
