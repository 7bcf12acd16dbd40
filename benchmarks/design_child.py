"""One ``synth.design`` in a fresh process, serial (no forked job), after a line of set-up code: its CPU seconds,
status, controller and objective. The benchmarks that compare two settings of the design run each side so, so
that neither inherits the other's caches."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, sys, time, warnings
warnings.simplefilter("ignore")
sys.path.insert(0, {root!r})
{setup}
from synth.forked import allow_fork
from synth import design, parse_spec
allow_fork(False)
spec = {spec}
if isinstance(spec, list):
    from benchmarks.design_problems import problem
    spec = problem(*spec).spec
t = time.process_time()
r = design(parse_spec(spec))
cpu = time.process_time() - t
print(json.dumps({{"cpu": cpu, "status": r.status, "controller": str(r.controller),
                  "parameters": None if r.controller is None else dict(r.controller.parameters),
                  "objective": r.objective["value"] if r.feasible and r.objective else None}}, default=float))
"""


def run_design(spec: object, setup: str) -> dict:
    """Design ``spec`` (a spec dict, or ``[seed, index]`` of :func:`benchmarks.design_problems.problem`) in a
    child process that first runs ``setup``; the child's record."""
    code = CHILD.format(root=str(ROOT), setup=setup, spec=repr(spec))
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])
