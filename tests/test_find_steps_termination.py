"""find_steps ends on every input: a constant input is an error naming the column (the search never advanced and
grew its list of steps without end: identify on a constant part of a record hung), and a sample lying on both
thresholds (hysteresis 0) is one level change, not an endless series. Run in a child process with a time limit,
so that a regression fails instead of hanging the suite."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SCRIPT = """
import numpy as np
from synth.data.record import Record
from synth.data import record_from_arrays
from synth.errors import DataError
from synth.ident.steps import find_steps
from synth.ident.identification import identify

t = np.arange(30) * 0.01
whole = record_from_arrays(t, np.r_[np.zeros(10), np.ones(20)], t)
constant = whole.segment(0.15, 0.29)  # a part of the record: no step in it
try:
    find_steps(constant)
    print("no error")
except DataError as exc:
    print("find_steps:", exc)
try:
    identify(constant, "K/(T*s+1)")
    print("no error")
except DataError as exc:
    print("identify:", exc)
s = find_steps(record_from_arrays(t, np.r_[np.zeros(10), 0.5, np.ones(19)], t), hysteresis=0.0)
print("steps:", s.index.tolist(), s.direction.tolist())
"""


def test_find_steps_ends_on_a_constant_input_and_on_a_sample_on_both_thresholds():
    done = subprocess.run([sys.executable, "-c", SCRIPT], env={**os.environ, "PYTHONPATH": str(ROOT)},
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.strip().splitlines()
    assert lines[0] == "find_steps: arrays: column 'input': the input is constant (1): no step in it"
    assert lines[1] == "identify: arrays: column 'input': the input is constant (1): no step in it"
    assert lines[2] == "steps: [10] [1]"
