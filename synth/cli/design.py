"""``synth design SPEC``: design the spec's controller and write a report."""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path
from typing import Any

from synth.progress import announce

__all__ = ["COMMAND", "DESCRIPTION", "EXIT_CODES", "HELP", "ORDER", "add_arguments", "run"]

COMMAND = "design"
ORDER = 20
HELP = "design the spec's controller and write reports/<name>/"
DESCRIPTION = """Design the controller a spec asks for and write a report.

Writes <out>/result.json, <out>/report.html and PNG figures (default
out: reports/<spec name>/). For one free parameter (e.g. a P gain) the exact
feasible set is computed and reported with what binds at each end.
Files in <out> that synth did not write are never overwritten.

example:
  synth design specs/x4_rotor.yaml
  synth design specs/x4_rotor_strict.yaml --json strict.json

exit codes: 0 designed, 1 infeasible, 2 bad input, 3 undetermined (no
stabilizing controller found to start from, or the best design failed its
dense re-check: the search could not decide)"""


EXIT_CODES = {"feasible": 0, "infeasible": 1, "undetermined": 3}
"""The command's exit code for each design status (2 is bad input)."""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("spec", help="spec file (YAML)")
    p.add_argument("--json", metavar="FILE", help="also write result.json's content to FILE ('-' for stdout)")
    p.add_argument("--out", metavar="DIR", help="report folder (default reports/<spec name>)")
    p.add_argument("--no-report", action="store_true", help="skip the HTML report and figures")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing; use the exit code")


def _prepare_report(spec: Any) -> dict[str, Any] | None:
    """What the report will need, made ready on this core while the design runs on the other: its modules,
    matplotlib's text machinery, the seed paper's section when the spec asks for it (it depends on the spec
    alone and is cached), the gain-set figure's slack curves (the spec alone) and, when the spec simulates,
    the compiled simulation kernels. Returns the curves (None without one free parameter)."""
    from synth.report.design_report import slack_curves
    from synth.report.figures import warm_up

    warm_up()
    if spec.analysis.paper is not None:
        from synth.report.paper_section import paper_section_data

        paper_section_data(spec)
    curves = slack_curves(spec) if len(spec.controller.free_parameters()) == 1 else None
    # a requirement type with a simulation field simulates (a no_limit_cycle verdict is confirmed by simulated
    # steps even when the spec has no simulation block)
    if spec.simulation is not None or any(hasattr(r, "simulation") for r in spec.requirements):
        from synth.sim.verdict import warm_up as warm_simulation

        warm_simulation()
    return curves


def _design_and_report(args: argparse.Namespace, spec: Any) -> tuple[Any, dict[str, Any] | None, Path]:
    """The design, and unless ``--no-report`` the report's files: the result, result.json's content (None
    without a report) and the report folder."""
    from synth.design import design_jobs
    from synth.forked import run_beside
    from synth.report.studies import spec_studies

    out_dir = Path(args.out) if args.out else Path("reports") / spec.name
    jobs, combine = design_jobs(spec)  # a PI/PID with and without integral action: two jobs
    if args.no_report:  # the jobs on both cores all the same (servo_pid: 3.4 -> 1.9 s)
        rest, first = run_beside(jobs[1:], jobs[0])
        return combine([first, *rest]), None, out_dir
    studies = spec_studies(spec)  # and the report's studies that need the spec alone
    # the design on the other core while this one loads the report's modules (synth.forked); with nothing else
    # to do here afterwards, this core is lent to the design's guesses (synth.speculation)
    beside = [*jobs, *(job for _, job in studies)]
    results, curves = run_beside(beside, lambda: _prepare_report(spec), lend_core=len(beside) == 1)
    result = combine(results[:len(jobs)])
    studied = {name: value for (name, _), value in zip(studies, results[len(jobs):])}
    from synth.report.design_report import write_design_report

    announce("writing the report")
    command = "synth design " + shlex.quote(args.spec)
    if args.out:
        command += f" --out {shlex.quote(args.out)}"
    files = write_design_report(spec, result, out_dir, command=command, force=args.force, curves=curves,
                                studies=studied)
    return result, json.loads(files.result_json.read_text(encoding="utf-8")), out_dir


def run(args: argparse.Namespace) -> int:
    from synth.cli._outputs import check_outputs, spec_name
    from synth.cli._table import print_requirements
    from synth.outputs import dump_json, write_json
    from synth.progress import StageLine
    from synth.requirements.base import fmt
    from synth.spec import load_spec

    name = args.out or spec_name(args.spec)  # refuse before any computation (the spec's plant may be identified)
    folder = None if args.no_report or not name else (Path(args.out) if args.out else Path("reports") / name)
    check_outputs(folder, ["result.json", "report.html"], [args.json], args.force, inputs=[args.spec])
    spec = load_spec(args.spec)
    say = (lambda *a: None) if args.quiet or args.json == "-" else print
    with StageLine("design", enabled=False if args.quiet or args.json == "-" else None):
        result, data, out_dir = _design_and_report(args, spec)
    if args.json:
        if data is None:
            from synth.report.design_report import report_data

            data = report_data(spec, result)
        payload = {k: v for k, v in data.items() if k != "generator"}
        if args.json == "-":
            sys.stdout.write(dump_json(payload))
        else:
            write_json(args.json, payload, force=args.force)
    say(f"{spec.name}: {result.status.upper()}")
    say(result.verdict)
    if result.gain_set is not None:
        gs = result.gain_set
        say(f"feasible {gs.parameter}: "
            + (", ".join(f"[{fmt(a, 6)}, {fmt(b, 6)}]" for a, b in gs.as_list()) or "none"))
    shown = result.check or result.compromise
    if shown is not None and not (args.quiet or args.json == "-"):
        print()
        if result.compromise is not None:
            print(f"best compromise (NOT a solution): {result.compromise.controller}")
        print_requirements(shown.requirements, list(spec.requirements), sys.stdout)
    if not args.no_report:
        say(f"\nreport: {out_dir / 'report.html'}")
    return EXIT_CODES[result.status]
