"""Whole CLI commands of the README, timed in fresh processes beside a baseline measured in the same run.

The baseline is another checkout of synth (by default a ``git worktree`` of ``--baseline-ref`` made in a
temporary folder); each command runs with ``PYTHONPATH`` pointing at one checkout and its working directory
there, alternately baseline and current, and the best of ``--repeat`` runs is kept (the machine is shared:
the minimum is the least disturbed run). Every command is run once untimed first on each side, so
first-use work (the synthetic X-4 record, numba's compile cache, the results kept on disk by
:mod:`synth.disk_cache`: the identification, the report's spec-only studies, the X-4 paper section) is excluded
("warm"); two rows run with those caches off (the main job, ``specs/x4_rotor.yaml``), so that what they keep is
timed too. Python's bytecode cache counts as first-use work too: the commands run without
``PYTHONDONTWRITEBYTECODE`` (which some shells and containers set), so the warm-up writes ``__pycache__`` on
both sides as an installed copy's first run does, and no timed run recompiles synth's modules. CPU time
(user + system of the command) is printed beside the wall time: on a loaded machine it moves far less than
the wall time.

Run:  python benchmarks/cli_speed.py [--repeat 3] [--baseline-ref main | --baseline DIR] [--quick] [--long-delay]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PI_SPEC = """\
name: x4_pi_delay
description: "X-4 rotor, 20 ms in-loop delay, PI: |S| <= -15 dB on [0.01, 5] rad/s, peak |S| <= 6 dB"
plant:
  tf: "23*(s+0.43)/((s+9.6)*(s+0.54))"
  delay: 0.02
  input: {name: throttle, unit: PWM}
  output: {name: rotor speed, unit: rad/s}
controller:
  type: PI
  bounds: {kp: [0, 5], ki: [0, 200]}
requirements:
  - {type: sensitivity, max_db: -15, band: [0.01, 5]}
  - {type: peak_sensitivity, max_db: 6}
objective: {maximize: integral_gain}
"""


P_SPEC = """\
name: dc_motor_p
description: "A DC motor speed loop nobody here tuned, P control: |S| <= -6 dB below 2 rad/s, margins"
plant:
  tf: "120/((s+4)*(s+60))"
  delay: 0.005
controller:
  type: P
  bounds: {kp: [0, 30]}
requirements:
  - {type: sensitivity, max_db: -6, band: [0, 2]}
  - {type: margins, gain_margin_db: 6, phase_margin_deg: 45}
  - {type: bandwidth, min: 5}
objective: {maximize: bandwidth}
"""

PID_SPEC = """\
name: servo_pid
description: "A position servo (integrator, lightly damped mode), PID with a fixed derivative filter"
plant:
  tf: "400/(s*(s^2+4*s+400))"
  delay: 0.002
controller:
  type: PID
  bounds: {kp: [0, 5], ki: [0, 5], kd: [0, 0.5], tf: [0.005, 0.005]}
requirements:
  - {type: peak_sensitivity, max_db: 6}
  - {type: margins, gain_margin_db: 6, phase_margin_deg: 40}
  - {type: bandwidth, min: 2}
objective: {maximize: bandwidth}
"""

PID_STEP_SPEC = """\
name: pid_step
description: "A third-order plant, PID with a fixed derivative filter: overshoot <= 5 %, settling <= 4 s"
plant:
  tf: "5/((s+1)*(s+2)*(s+3))"
controller:
  type: PID
  bounds: {kp: [0, 20], ki: [0, 20], kd: [0, 10], tf: [0.01, 0.01]}
requirements:
  - {type: step_response, max_overshoot: 5, max_settling_time: 4}
objective: {maximize: integral_gain}
"""

PI_STEP_SPEC = """\
name: x4_pi_step
description: "X-4 rotor, 20 ms in-loop delay, PI: |S| <= -10 dB on [0.01, 1] rad/s, overshoot <= 10 %"
plant:
  tf: "23*(s+0.43)/((s+9.6)*(s+0.54))"
  delay: 0.02
controller:
  type: PI
  bounds: {kp: [0, 10], ki: [0, 200]}
requirements:
  - {type: sensitivity, max_db: -10, band: [0.01, 1]}
  - {type: step_response, max_overshoot: 10}
objective: {maximize: integral_gain}
"""


LONG_DELAY_SPEC = """\
name: dead_time_{delay}
description: "A dead-time process: 1/(s+1) behind {delay} s, P control, bandwidth floor"
plant:
  tf: "1/(s+1)"
  delay: {delay}
controller:
  type: P
  bounds: {{kp: [0, 1000]}}
requirements:
  - {{type: bandwidth, min: 0.001}}
"""


def long_delay_cases(tmp: Path) -> dict[str, list[str]]:
    """``--long-delay``: P designs behind delays long against the plant (the stabilizing set's boundaries, one
    per turn of the delay's phase beyond the critical gain, number in the thousands)."""
    out = {}
    for delay in (5, 20):
        spec = tmp / f"dead_time_{delay}.yaml"
        spec.write_text(LONG_DELAY_SPEC.format(delay=delay), encoding="utf-8")
        out[f"synth design dead_time_{delay}.yaml (1/(s+1) behind {delay} s, P up to 1000, with report)"] = \
            ["design", str(spec), "--out", "{out}"]
    return out


def cases(tmp: Path) -> dict[str, list[str]]:
    """Label -> command arguments after ``python -m synth`` (``{out}`` is replaced by a fresh folder; a leading
    ``ENV=value`` item is set in the command's environment)."""
    pi = tmp / "x4_pi_delay.yaml"
    pi.write_text(PI_SPEC, encoding="utf-8")
    p_spec, pid_spec = tmp / "dc_motor_p.yaml", tmp / "servo_pid.yaml"
    p_spec.write_text(P_SPEC, encoding="utf-8")
    pid_spec.write_text(PID_SPEC, encoding="utf-8")
    pid_step, pi_step = tmp / "pid_step.yaml", tmp / "x4_pi_step.yaml"
    pid_step.write_text(PID_STEP_SPEC, encoding="utf-8")
    pi_step.write_text(PI_STEP_SPEC, encoding="utf-8")
    return {
        "synth design specs/x4_rotor_from_data.yaml (README main job)":
            ["design", "specs/x4_rotor_from_data.yaml", "--out", "{out}"],
        "main job, nothing reused (SYNTH_IDENTIFY_CACHE=off SYNTH_RESULT_CACHE=off)":
            ["SYNTH_IDENTIFY_CACHE=off", "SYNTH_RESULT_CACHE=off", "design", "specs/x4_rotor_from_data.yaml", "--out",
             "{out}"],
        "synth design specs/x4_rotor.yaml": ["design", "specs/x4_rotor.yaml", "--out", "{out}"],
        "x4_rotor, studies not reused (SYNTH_RESULT_CACHE=off)":
            ["SYNTH_RESULT_CACHE=off", "design", "specs/x4_rotor.yaml", "--out", "{out}"],
        "synth design x4_pi_delay.yaml (PI, 20 ms delay, with report)": ["design", str(pi), "--out", "{out}"],
        "synth design specs/x4_rotor_pi.yaml (PI, nonlinear step, with report)":
            ["design", "specs/x4_rotor_pi.yaml", "--out", "{out}"],
        "synth design specs/x4_rotor_robust.yaml (PI over 3 plants, with report)":
            ["design", "specs/x4_rotor_robust.yaml", "--out", "{out}"],
        "synth design dc_motor_p.yaml (P, with report)": ["design", str(p_spec), "--out", "{out}"],
        "synth design servo_pid.yaml (PID, with report)": ["design", str(pid_spec), "--out", "{out}"],
        "synth design pid_step.yaml (PID, step-response limits, with report)": ["design", str(pid_step), "--out", "{out}"],
        "synth design x4_pi_step.yaml (PI, 20 ms delay, overshoot limit, with report)":
            ["design", str(pi_step), "--out", "{out}"],
        "synth check specs/x4_rotor.yaml --controller P(3)":
            ["check", "specs/x4_rotor.yaml", "--controller", "P(3)"],
    }


def run(root: Path, args: list[str], tmp: Path) -> tuple[float, float]:
    """Wall and CPU (user + system) time of ``python -m synth ARGS`` in ``root`` with ``PYTHONPATH=root``;
    raises on failure."""
    out = Path(tempfile.mkdtemp(dir=tmp))
    extra = dict(a.split("=", 1) for a in args if "=" in a and a.split("=", 1)[0].isupper())
    args = [a for a in args if not ("=" in a and a.split("=", 1)[0].isupper())]
    argv = [sys.executable, "-m", "synth", *[a.replace("{out}", str(out / "r")) for a in args]]
    env = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"},  # as a user's install
           "PYTHONPATH": str(root), **extra}
    elapsed, cpu, _ = timed_run(argv, root, env)
    return elapsed, cpu


def timed_run(argv: list[str], root: Path, env: dict[str, str], codes: tuple[int, ...] = (0, 1),
              timeout: float | None = None) -> tuple[float, float, subprocess.CompletedProcess]:
    """Wall and CPU (user + system) time of the command ``argv`` run in ``root``, and the finished process;
    raises unless it exits with one of ``codes`` (default 0 or 1: a design that is infeasible, a check or a fit that
    fails, is still a run), and ``subprocess.TimeoutExpired`` when it runs longer than ``timeout`` wall seconds."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(argv, cwd=root, env=env, capture_output=True, text=True, timeout=timeout)
    elapsed = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if proc.returncode not in codes:
        raise RuntimeError(f"{' '.join(argv)} in {root} exited {proc.returncode}:\n{proc.stderr[-2000:]}")
    return elapsed, cpu, proc


def baseline_checkout(ref: str, tmp: Path) -> Path:
    """A detached ``git worktree`` of ``ref`` in ``tmp`` (removed by :func:`remove_checkout`)."""
    path = tmp / "baseline"
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(path), ref],
                   check=True, capture_output=True)
    return path


def remove_checkout(path: Path) -> None:
    """Remove a worktree made by :func:`baseline_checkout`."""
    subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(path)], capture_output=True)


@contextlib.contextmanager
def baseline_tree(ref: str, prefix: str) -> Iterator[Path]:
    """A temporary :func:`baseline_checkout` of ``ref``, removed with its folder on leaving the block."""
    with tempfile.TemporaryDirectory(prefix=prefix) as tmp:
        path = baseline_checkout(ref, Path(tmp))
        try:
            yield path
        finally:
            remove_checkout(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per command and side (best kept)")
    parser.add_argument("--baseline-ref", default="main", help="git ref of the baseline (default main)")
    parser.add_argument("--baseline", type=Path, help="an existing checkout to use as the baseline instead")
    parser.add_argument("--quick", action="store_true", help="one timed run, and only the check command")
    parser.add_argument("--long-delay", action="store_true",
                        help="instead of the README's commands, P designs behind long delays (long_delay_cases)")
    args = parser.parse_args()
    repeat = 1 if args.quick else args.repeat
    with tempfile.TemporaryDirectory(prefix="synth-cli-speed-") as tmp_name:
        tmp = Path(tmp_name)
        base = args.baseline.resolve() if args.baseline else baseline_checkout(args.baseline_ref, tmp)
        try:
            todo = long_delay_cases(tmp) if args.long_delay else cases(tmp)
            if args.quick:
                todo = {k: v for k, v in todo.items() if v[0] == "check"}
            sides = {"baseline": base, "current": ROOT}
            best: dict[tuple[str, str], float] = {}
            cpu: dict[tuple[str, str], float] = {}
            for label, argv in todo.items():
                for root in sides.values():  # warm-up: first-use data, caches
                    run(root, argv, tmp)
                for _ in range(repeat):
                    for side, root in sides.items():  # interleaved, so both sides see the same load
                        t, c = run(root, argv, tmp)
                        best[label, side] = min(best.get((label, side), float("inf")), t)
                        cpu[label, side] = min(cpu.get((label, side), float("inf")), c)
            print(f"baseline: {base} ({args.baseline_ref if not args.baseline else 'given'}); "
                  f"current: {ROOT}; best of {repeat}, warm; load average {os.getloadavg()[0]:.1f}")
            print()
            print("| command | baseline wall [s] | current wall [s] | speed-up | baseline CPU [s] | current CPU [s] |")
            print("|---|---|---|---|---|---|")
            for label in todo:
                b, c = best[label, "baseline"], best[label, "current"]
                print(f"| `{label}` | {b:.2f} | {c:.2f} | {b / c:.1f}x | {cpu[label, 'baseline']:.2f} | "
                      f"{cpu[label, 'current']:.2f} |")
        finally:
            if not args.baseline:
                remove_checkout(base)


if __name__ == "__main__":
    main()
