"""``synth diagnose`` on the DC motor's real no-load runs, as docs/gap.md runs it: this checkout beside a baseline.

The commands are the documented ones (../shared/data/dcmotor_speed_lab: the delay-free two-lag model fitted to run
06, every default candidate): the round robin over the three no-load runs, and run 06 held out on 09 and 12. Each
side runs each command in a fresh process, one after the other (the same load); the time is the CPU time of the
command's process and its worker processes, the answer the JSON's verdict (effects and status). Skipped with a
message where ../shared/data is absent.

Run:  python benchmarks/gap/realdata_speed.py [--baseline-ref main] [--repeat 1]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT.parent / "shared" / "data" / "dcmotor_speed_lab"
RUNS = ("06_dc_step_5_15_00.mat", "09_dc_step_20_25_00.mat", "12_dc_step_20_25_00.mat")
PLANT = "246.1/((0.1672*s+1)*(0.1659*s+1))"
COMMON = ["--time", "Zeit", "--input", "Motorspannung", "--output", "Geschwindigkeit", "--input-unit", "V",
          "--output-unit", "rpm"]


def commands() -> dict[str, list[str]]:
    """The documented diagnose commands, by label."""
    runs = [str(DATA / name) for name in RUNS]
    base = ["diagnose", "--plant", PLANT, "--data", runs[0], "--validate", runs[1], "--validate", runs[2], *COMMON]
    return {"round robin over 06, 09, 12": [*base, "--round-robin"], "06 held out on 09 and 12": base}


def run(root: Path, argv: list[str], out: Path) -> tuple[float, str]:
    """CPU seconds (process and children) and the verdict of one command with ``root``'s synth."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    from benchmarks.cli_speed import timed_run

    _, cpu, proc = timed_run([sys.executable, "-m", "synth", *argv, "--out", str(out), "--force", "--json", "-"],
                             root, env)
    try:
        verdict = json.loads(proc.stdout)["verdict"]
        answer = f"{verdict.get('status')}: {', '.join(verdict.get('effects', [])) or '-'}"
    except (ValueError, KeyError):
        answer = f"exit {proc.returncode}: {proc.stderr.strip().splitlines()[-1][:60] if proc.stderr.strip() else ''}"
    return cpu, answer


def main() -> None:
    from benchmarks.cli_speed import baseline_tree

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline-ref", default="main")
    parser.add_argument("--repeat", type=int, default=1, help="runs per command and side (the least CPU kept)")
    args = parser.parse_args()
    if not DATA.is_dir():
        print(f"skipped: {DATA} is absent")
        return
    rows = []
    with tempfile.TemporaryDirectory(prefix="synth-gap-realdata-") as tmp, \
            baseline_tree(args.baseline_ref, "synth-gap-realdata-base-") as base:
        for label, argv in commands().items():
            best: dict[str, tuple[float, str]] = {}
            for _ in range(args.repeat):
                for side, root in (("this", ROOT), ("baseline", base)):
                    cpu, answer = run(root, argv, Path(tmp) / side)
                    if side not in best or cpu < best[side][0]:
                        best[side] = (cpu, answer)
            rows.append((label, best))
    print(f"`synth diagnose` on the DC motor's no-load runs (docs/gap.md), CPU seconds, least of {args.repeat}")
    print(f"| command | this checkout [s] | baseline {args.baseline_ref} [s] | ratio | verdict (this / baseline) |")
    print("|---|---|---|---|---|")
    for label, best in rows:
        (mine, a), (theirs, b) = best["this"], best["baseline"]
        print(f"| {label} | {mine:.1f} | {theirs:.1f} | {mine / theirs:.2f} | {a} / {b} |")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
