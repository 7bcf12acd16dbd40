"""``synth tradeoff SPEC --sweep PATH=start:stop:count``: design across swept requirements."""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

__all__ = ["COMMAND", "DESCRIPTION", "HELP", "ORDER", "add_arguments", "run"]

COMMAND = "tradeoff"
ORDER = 30
HELP = "sweep one or two spec values and report the Pareto front"
DESCRIPTION = """Design the spec at every point of one or two sweeps and write
<out>/tradeoff.{csv,json,html,png} (default out: reports/<spec name>/).

A sweep is PATH=start:stop:count or PATH=v1,v2,...; PATH picks a value in the
spec: requirements.<label|type|index>.<key>, plant.delay, controller.bounds.kp.1, ...

Runs in a local process pool (one warm-started chunk of points per worker),
or on a Dask distributed cluster with --scheduler ADDRESS.

example:
  synth tradeoff specs/x4_rotor_pi.yaml --sweep "requirements.bandwidth.min=40:100:13"
  synth tradeoff specs/x4_rotor.yaml --sweep "requirements.slew_rate.rate_limit=2000:10000:5" \\
      --sweep "requirements.sensitivity_static.max_db=-20:-10:5"

exit codes: 0 at least one point feasible, 1 none, 2 bad input"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("spec", help="spec file (YAML)")
    p.add_argument("--sweep", action="append", required=True, metavar="PATH=RANGE",
                   help="swept value (give once or twice)")
    p.add_argument("--out", metavar="DIR", help="report folder (default reports/<spec name>)")
    p.add_argument("--workers", type=int, help="local worker processes (default: CPU count)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address, e.g. tcp://10.0.0.5:8786")
    p.add_argument("--json", metavar="FILE", help="also write the result as JSON ('-' for stdout)")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar or table")


def run(args: argparse.Namespace) -> int:
    from synth.cli._outputs import check_outputs, spec_name
    from synth.cli._table import table
    from synth.errors import SpecError
    from synth.outputs import dump_json, write_json
    from synth.report.tradeoff_report import write_tradeoff_report
    from synth.requirements.base import fmt
    from synth.spec import load_spec
    from synth.synthesis.tradeoff import Sweep, tradeoff

    name = args.out or spec_name(args.spec)  # refuse before any computation
    check_outputs((Path(args.out) if args.out else Path("reports") / name) if name else None,
                  ["tradeoff.csv", "tradeoff.json", "tradeoff.html", "tradeoff.png"], [args.json], args.force,
                  inputs=[args.spec])
    spec = load_spec(args.spec)
    sweeps = [Sweep.parse(s) for s in args.sweep]
    if len(sweeps) > 2:
        raise SpecError("give at most two sweeps", where="--sweep")
    if args.workers is not None and args.workers < 1:
        raise SpecError("must be at least 1", where="--workers")
    total = len(sweeps[0].values) * (len(sweeps[1].values) if len(sweeps) > 1 else 1)
    bar = None
    show = not args.quiet and args.json != "-"

    def progress(done: int, _total: int) -> None:
        nonlocal bar
        if bar is None and show:  # drawn once the sweep is valid: a bad one is one line, without a bar
            from tqdm import tqdm

            bar = tqdm(total=total, desc=f"{spec.name} trade-off", unit="design", file=sys.stderr)
        if bar is not None:
            bar.update(done - bar.n)

    result = tradeoff(spec, sweeps, scheduler=args.scheduler, workers=args.workers, progress=progress)
    if bar is not None:
        bar.close()
    out_dir = Path(args.out) if args.out else Path("reports") / spec.name
    command = "synth tradeoff " + shlex.quote(args.spec) + "".join(f" --sweep {shlex.quote(s)}" for s in args.sweep)
    files = write_tradeoff_report(result, out_dir, command=command, force=args.force)
    from synth.report.templating import reproducible

    saved = reproducible(result.to_dict())  # as tradeoff.json: no wall-clock times, the same bytes on a re-run
    if args.json == "-":
        sys.stdout.write(dump_json(saved))
    elif args.json:
        write_json(args.json, saved, force=args.force)
    if not args.quiet and args.json != "-":
        rows = [[*(fmt(p.values[s.path]) for s in sweeps), {"feasible": "yes", "infeasible": "no"}.get(p.status, p.status),
                 fmt(p.objective),
                 ", ".join(p.binding), "*" if p.pareto else ""] for p in result.points]
        print(table([s.path for s in sweeps] + ["feasible", "objective", "binding", "Pareto"], rows))
        print(f"\n{sum(p.feasible for p in result.points)} of {len(result.points)} feasible; "
              f"{result.scheduler}; {result.seconds:.1f} s\nreport: {files.html}")
    return 0 if any(p.feasible for p in result.points) else 1
