"""synth diagnose killed mid-run: no worker survives (SIGTERM, SIGKILL); SIGTERM with --json writes the partial result."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil
import pytest

from synth.ident.simulate import simulate_plant
from synth.plant import Plant
from synth.sim.blocks import RateLimit

PLANT = "20/(s+10)"
ROOT = Path(__file__).resolve().parents[1]

# one worker: the 300,000-sample record is written once, and no two diagnoses with their own workers run at once
pytestmark = [pytest.mark.xdist_group("gap_interrupt"), pytest.mark.slow]  # 24 s on one worker: started first


@pytest.fixture(scope="module")
def big_csv(tmp_path_factory):
    """300,000 samples with a rate limit: the diagnosis runs about 10 s on 2 quiet cores, 4 s of it after the
    workers start (100,000 samples left 1.4 s there, which a loaded CI machine once used up before the
    signal was sent: the run ended with exit code 0)."""
    t = np.arange(0, 3000, 0.01)
    u = np.where((t % 2) >= 1, 100.0, 0.0) * (1 + 0.5 * np.sin(0.1 * t))
    y = simulate_plant(Plant.from_string(PLANT), t, RateLimit(400.0).apply(u, 0.01))
    y = y + 0.2 * np.random.default_rng(0).normal(size=t.size)
    path = tmp_path_factory.mktemp("big") / "big.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,pwm,speed", comments="")
    return path


def start(csv: Path, out: Path) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, "-m", "synth", "diagnose", "--plant", PLANT, "--data", str(csv), "--time", "t",
           "--input", "pwm", "--output", "speed", "--workers", "2", "--no-report", "--json", str(out),
           "--candidates", "rate_limit,delay,lag,saturation,backlash,deadzone"]
    return subprocess.Popen(cmd, env=env, cwd=str(ROOT), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def wait_for_workers(proc: subprocess.Popen, timeout: float = 120.0) -> list[int]:
    """The pids of the diagnosis's worker processes once the pool is running."""
    parent = psutil.Process(proc.pid)
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if proc.poll() is not None:
            pytest.fail(f"the diagnosis ended (code {proc.returncode}) before its workers started: {proc.stderr.read()}")
        kids = [c.pid for c in parent.children(recursive=True)]
        if len(kids) >= 2:
            return kids
        time.sleep(0.05)
    proc.kill()
    pytest.fail("no worker processes within the timeout")


def survivors(pids: list[int], timeout: float = 10.0) -> list[int]:
    end = time.monotonic() + timeout
    alive = pids
    while time.monotonic() < end:
        alive = []
        for pid in pids:
            try:
                if psutil.Process(pid).status() != psutil.STATUS_ZOMBIE:
                    alive.append(pid)
            except psutil.NoSuchProcess:
                pass
        if not alive:
            return []
        time.sleep(0.1)
    return alive


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_sigterm_or_sigint_leaves_no_worker_and_writes_partial_json(big_csv, tmp_path, sig):
    out = tmp_path / "gap.json"
    proc = start(big_csv, out)
    kids = wait_for_workers(proc)
    assert proc.poll() is None, "the diagnosis ended before the signal could be sent: the record is too short"
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + sig
    assert survivors(kids) == []
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and f"interrupted by {sig.name}" in lines[0] and "kept gap, where" in lines[0], err
    data = json.loads(out.read_text())
    assert data["partial"] is True and data["interrupted_by"] == sig.name
    assert data["kept"] == ["gap", "where"] and data["missing"] == ["effects", "verdict"]
    assert data["gap"]["nrmse"] > 0.0 and data["stage"] == "attribution"


def test_sigkill_of_the_parent_leaves_no_worker(big_csv, tmp_path):
    proc = start(big_csv, tmp_path / "gap.json")
    kids = wait_for_workers(proc)
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=60)
    assert survivors(kids) == []
