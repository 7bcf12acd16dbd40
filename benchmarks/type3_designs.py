"""PID designs on random type-3 loops (a double integrator with a zero, the class where a converged polish was
called a local optimum with a way up left; session 41), on this code and on a baseline checkout side by side.

Each problem: ``K (s + z) / (s^2 (s + p1)(s + p2))``, a PID with a fixed derivative filter, gain and phase margins and
a peak |S| bound drawn at random, maximize ``ki``. Every design is checked by python-control (written here, apart
from synth's check): closed-loop poles of the feedback loop, every gain margin (the nearer of the upward and the
downward one), every phase margin, peak |S| on 200,000 log-spaced points.

Run: ``python benchmarks/type3_designs.py --n 20 --baseline-ref b066632``
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import control as ct
import numpy as np

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, sys, time
from synth.design import design
from synth.spec import parse_spec
spec = parse_spec(json.loads(sys.argv[1]))
t = time.process_time()
r = design(spec)
opt = r.extras.get("optimality", {}) if r.feasible else {}
print(json.dumps({"feasible": r.feasible, "params": r.controller.parameters if r.feasible else None,
                  "local": opt.get("local"), "cpu": time.process_time() - t}))
"""


def problem(seed: int) -> dict:
    """The seeded spec."""
    rng = np.random.default_rng(seed)
    z, p1, p2 = 10 ** rng.uniform(-0.7, 0.3), 10 ** rng.uniform(-1.2, -0.3), 10 ** rng.uniform(0.2, 1.0)
    k = float(10 ** rng.uniform(0, 1.2))
    tf = f"{k:.6g}*(s+{z:.6g})/(s*s*(s+{p1:.6g})*(s+{p2:.6g}))"
    return {"name": f"type3_{seed}", "plant": {"tf": tf},
            "controller": {"type": "PID", "bounds": {"kp": [0, 10], "ki": [0, 10], "kd": [0, 5],
                                                     "tf": [0.05, 0.05]}},
            "requirements": [{"type": "margins", "gain_margin_db": float(rng.uniform(4, 8)),
                              "phase_margin_deg": float(rng.uniform(30, 50))},
                             {"type": "peak_sensitivity", "max_db": float(rng.uniform(6, 10))}],
            "objective": {"maximize": "integral_gain"}}


def reference_check(spec: dict, p: dict) -> bool:
    """python-control's verdict on the design (margins 0.01 dB / 0.01 deg and peak 0.01 dB of tolerance)."""
    s = ct.tf("s")
    num_den = spec["plant"]["tf"]
    G = eval(num_den.replace("^", "**"), {"s": s})  # the generator's own text: products and sums of s
    L = (p["kp"] + p["ki"] / s + p["kd"] * s / (p["tf"] * s + 1)) * G
    if not np.all(np.real(ct.poles(ct.feedback(L, 1))) < 0):
        return False
    gms, pms = ct.stability_margins(L, returnall=True)[:2]
    gm = float(np.min(np.abs(20 * np.log10(gms)))) if np.size(gms) else np.inf
    pm = float(np.min(pms)) if np.size(pms) else np.inf
    w = np.logspace(-4, 3, 200_000)
    peak = float(20 * np.log10(np.max(np.abs(1 / (1 + L(1j * w))))))
    m, ps = spec["requirements"]
    return gm >= m["gain_margin_db"] - 0.01 and pm >= m["phase_margin_deg"] - 0.01 and peak <= ps["max_db"] + 0.01


def run(checkout: Path, spec: dict) -> dict:
    out = subprocess.run([sys.executable, "-c", CHILD, json.dumps(spec)], cwd=checkout, capture_output=True,
                         text=True, env={"PYTHONPATH": str(checkout), "PATH": "/usr/bin:/bin", "SYNTH_JOBS": "1"})
    if out.returncode:
        return {"feasible": False, "error": out.stderr.strip().splitlines()[-1]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=20)
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--baseline-ref", default="b066632")
    ap.add_argument("--json", help="write the rows here")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp) / "baseline"
        subprocess.run(["git", "worktree", "add", "-f", "--detach", str(base), args.baseline_ref], cwd=ROOT,
                       check=True, capture_output=True)
        try:
            rows = []
            for seed in range(args.start, args.start + args.n):
                spec = problem(seed)
                old, new = run(base, spec), run(ROOT, spec)
                row = {"seed": seed, "baseline": old, "current": new}
                for side in ("baseline", "current"):
                    r = row[side]
                    r["reference_passes"] = bool(r.get("feasible") and reference_check(spec, r["params"]))
                rows.append(row)
                ki = [r["params"]["ki"] if r.get("feasible") else float("nan") for r in (old, new)]
                print(f"{seed:3d} ki {ki[0]:.5g} -> {ki[1]:.5g}  local {old.get('local')} -> {new.get('local')}  "
                      f"ref {old['reference_passes']} {new['reference_passes']}  cpu {old.get('cpu', 0):.1f} -> "
                      f"{new.get('cpu', 0):.1f} s", flush=True)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(base)], cwd=ROOT, capture_output=True)
    both = [r for r in rows if r["baseline"].get("feasible") and r["current"].get("feasible")]
    gains = np.array([r["current"]["params"]["ki"] / r["baseline"]["params"]["ki"] - 1 for r in both
                      if r["baseline"]["params"]["ki"] > 0])
    print("\n| measure | baseline | current |\n|---|---|---|")
    for label, key in (("feasible designs", "feasible"), ("passing python-control's check", "reference_passes")):
        print(f"| {label} | {sum(bool(r['baseline'].get(key)) for r in rows)} / {len(rows)} | "
              f"{sum(bool(r['current'].get(key)) for r in rows)} / {len(rows)} |")
    print(f"| called a local optimum | {sum(bool(r['baseline'].get('local')) for r in rows)} | "
          f"{sum(bool(r['current'].get('local')) for r in rows)} |")
    if gains.size:
        print(f"| ki, current over baseline: median / max gain; designs > 1 % better / > 1 % worse | | "
              f"{100 * np.median(gains):.2f} % / {100 * gains.max():.1f} %; {int(np.sum(gains > 0.01))} / "
              f"{int(np.sum(gains < -0.01))} |")
    cpu = [np.median([r[s].get("cpu", np.nan) for r in rows]) for s in ("baseline", "current")]
    print(f"| design CPU median [s] | {cpu[0]:.2f} | {cpu[1]:.2f} |")
    if args.json:
        Path(args.json).write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
