"""map_jobs interrupted while the pool is still handing out a job that is slow to pickle: it returns at once.

A job sent through the pool's task pipe whole could still be pickling when the interruption came: the pool's
task thread then wrote it into a pipe no terminated worker would read and ``Pool.terminate`` waited for
that thread forever (``synth diagnose`` hung on a SIGTERM). The script below reproduces that order of events
deterministically: two jobs keep both workers busy, the third takes 3 s to pickle into 4 MB (more than a
pipe holds) and the signal comes after 1 s, while it is pickling.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

SCRIPT = """
import os, signal, sys, threading, time
from synth.worker_pool import map_jobs

class SlowToPickle:
    def __init__(self, i):
        self.i = i
    def __reduce__(self):  # the first two jobs keep both workers busy; the third is slow to pickle, and big
        if self.i >= 2:
            time.sleep(3.0)
        return (len, (b"x" * 4_000_000 if self.i >= 2 else b"",))

def work(job):
    time.sleep(60.0)
    return 0

class Stop(BaseException):
    pass

def handler(signum, frame):
    raise Stop

signal.signal(signal.SIGTERM, handler)
threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGTERM)).start()
try:
    map_jobs(work, [SlowToPickle(i) for i in range(4)], workers=2)
except Stop:
    sys.exit(143)
sys.exit(0)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="the pool is forked on Linux; elsewhere it pickles the jobs")
def test_an_interrupted_pool_does_not_wait_for_a_job_being_pickled():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-c", SCRIPT], env=env, start_new_session=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    start = time.monotonic()
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        pytest.fail("map_jobs hung after the interruption (the pool waited for a job being pickled)")
    assert proc.returncode == 143, err
    assert time.monotonic() - start < 15.0  # the workers' 60 s jobs were terminated, not waited for
