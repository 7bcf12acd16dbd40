"""synth tradeoff interrupted mid-sweep: SIGTERM leaves no worker running, a Ctrl-C to the process group ends it
within seconds (the executor's workers kept designing after a SIGTERM, orphaned, and a Ctrl-C waited ~45 s for
the chunks in progress)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

ROOT = Path(__file__).resolve().parents[1]

SPEC = """\
name: slow_sweep
plant:
  tf: "2/(s*(s+1))"
  delay: 0.5
controller:
  type: PI
  bounds: {kp: [0, 5], ki: [0, 2]}
requirements:
  - {type: margins, gain_margin_db: 6, phase_margin_deg: 40}
  - {type: delay_margin, min: 0.1}
  - {type: peak_sensitivity, max_db: 6}
  - {type: disk_margin, min: 0.3}
objective: {maximize: integral_gain}
"""


def start(tmp_path: Path) -> subprocess.Popen:
    spec = tmp_path / "slow.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    cmd = [sys.executable, "-m", "synth", "tradeoff", str(spec), "--sweep",
           "requirements.peak_sensitivity.max_db=3:10:40", "--out", str(tmp_path / "out"), "--workers", "2", "-q"]
    # SIGINT at its default, as a terminal starts a command: a suite launched in the background by a
    # non-interactive shell inherits SIGINT ignored, Python then keeps ignoring it, and the Ctrl-C never arrives
    return subprocess.Popen(cmd, cwd=str(ROOT), env={**os.environ, "PYTHONPATH": str(ROOT)},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_default_sigint)


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def workers_of(proc: subprocess.Popen, timeout: float = 120.0) -> list[psutil.Process]:
    parent = psutil.Process(proc.pid)
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        assert proc.poll() is None, "the sweep ended before its workers started"
        kids = parent.children(recursive=True)
        if len(kids) >= 2:
            time.sleep(1.0)  # the workers are designing (40 points take about a minute)
            return parent.children(recursive=True)
        time.sleep(0.05)
    pytest.fail("no worker processes within the timeout")


def alive(procs: list[psutil.Process], timeout: float = 10.0) -> list[int]:
    end = time.monotonic() + timeout
    left = procs
    while time.monotonic() < end:
        left = [p for p in procs if p.is_running() and p.status() != psutil.STATUS_ZOMBIE]
        if not left:
            return []
        time.sleep(0.1)
    return [p.pid for p in left]


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_an_interrupted_sweep_ends_at_once_and_leaves_no_worker(tmp_path, sig):
    proc = start(tmp_path)
    kids = workers_of(proc)
    sent = time.monotonic()
    if sig == signal.SIGINT:
        os.killpg(proc.pid, sig)  # a Ctrl-C reaches the whole process group
    else:
        proc.send_signal(sig)
    try:
        proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail(f"{sig.name}: the sweep did not end within 30 s")
    assert time.monotonic() - sent < 10.0
    assert proc.returncode == (130 if sig == signal.SIGINT else -signal.SIGTERM)
    left = alive(kids)
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert left == [], f"{sig.name} left workers running"
