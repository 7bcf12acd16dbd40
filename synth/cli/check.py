"""``synth check SPEC --controller "P(3)"``: is a controller good enough?"""

from __future__ import annotations

import argparse
import sys

__all__ = ["COMMAND", "DESCRIPTION", "HELP", "ORDER", "add_arguments", "run"]

COMMAND = "check"
ORDER = 10
HELP = "check a controller against every requirement of a spec"
DESCRIPTION = """Check a controller against every requirement of a spec file.

Prints each requirement's value, bound, slack (>= 0 met) and the frequency
where it binds. Closed-loop stability (exact, delay included) is always checked.

example:
  synth check specs/x4_rotor.yaml --controller "P(3)"
  synth check specs/x4_rotor.yaml --controller "PI(kp=1.2, ki=20)" --json out.json

exit codes: 0 all met, 1 something not met, 2 bad input"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("spec", help="spec file (YAML)")
    p.add_argument("--controller", "-c", required=True,
                   help='controller, e.g. "P(3)", "PI(kp=1.2, ki=20)", "PID(1, 2, 0.1, 0.01)"')
    p.add_argument("--json", metavar="FILE", help="also write the result as JSON ('-' for standard output)")
    p.add_argument("--force", action="store_true", help="overwrite a --json file synth did not write")
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing; use the exit code")


def run(args: argparse.Namespace) -> int:
    from synth.check import check
    from synth.cli._outputs import check_outputs
    from synth.cli._table import print_requirements
    from synth.controllers import Controller
    from synth.errors import ModelError
    from synth.outputs import dump_json, write_json
    from synth.spec import load_spec

    check_outputs(None, files=[args.json], force=args.force, inputs=[args.spec])  # before any computation
    spec = load_spec(args.spec)
    try:
        controller = Controller.from_string(args.controller)
    except ModelError as exc:
        raise exc.located("--controller") from None
    result = check(spec, controller)
    if args.json == "-":
        sys.stdout.write(dump_json(result.to_dict()))
    elif args.json:
        write_json(args.json, result.to_dict(), force=args.force)
    if not args.quiet and args.json != "-":
        print(f"{spec.name}: {controller}  [{controller.transfer_function_text()}]")
        print_requirements(result.requirements, list(spec.requirements), sys.stdout)
        print()
        print("all requirements met" if result.feasible else
              f"NOT met: {', '.join(r.label for r in result.failed())}")
    return 0 if result.feasible else 1
