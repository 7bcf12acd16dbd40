"""synth.forked.run_beside: results in order whichever process ran a job, exceptions raised here, a dead
child's jobs rerun here, serial when forking is off; and the design command's outputs are the same bytes
whether its figures and design ran beside each other or one after the other."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from synth.forked import allow_fork, run_beside

ROOT = Path(__file__).resolve().parents[1]


def _child_has_begun():
    """``(begin, wait)``: a job calls ``begin()`` as it starts; ``wait()`` (this process's own work) returns once
    a job has begun in another process (a loaded machine may start the child late: a fixed sleep here let this
    process take every job)."""
    import select

    read_end, write_end = os.pipe()
    parent = os.getpid()

    def begin():
        if os.getpid() != parent:
            os.write(write_end, b"x")

    def wait(required: bool = True):
        ready, _, _ = select.select([read_end], [], [], 60.0 if required else 3.0)
        assert ready or not required, "no job began in the child within 60 s"

    return begin, wait

@pytest.fixture(autouse=True)
def _fork_allowed(monkeypatch):
    monkeypatch.delenv("SYNTH_JOBS", raising=False)  # conftest turns the helper process off for the rest of the suite
    allow_fork(True)
    yield
    allow_fork(False)


def test_results_come_back_in_order_and_both_processes_take_jobs():
    import time

    begin, wait = _child_has_begun()

    def job(i: int):
        def run():
            begin()
            time.sleep(0.05)
            return i * i, os.getpid()
        return run

    results, mine = run_beside([job(i) for i in range(8)], lambda: wait() or "own")
    assert mine == "own"
    assert [r[0] for r in results] == [i * i for i in range(8)]
    pids = {r[1] for r in results}
    assert os.getpid() in pids and len(pids) == 2  # the child and, once its own work was done, this process


def test_an_exception_in_the_child_is_raised_here():
    def bad():
        raise ValueError("no such plant")

    with pytest.raises(ValueError, match="no such plant"):
        run_beside([lambda: 1, bad], lambda: None)


def test_a_result_that_does_not_pickle_is_computed_here_again():
    calls = []

    def unpicklable():
        calls.append(os.getpid())
        return lambda: 0  # a lambda does not pickle

    (value,), _ = run_beside([unpicklable], lambda: None)
    assert callable(value) and calls == [os.getpid()]  # this process's own call (the child's is lost)


def test_a_child_that_dies_leaves_its_jobs_to_this_process():
    def die_in_child():
        if os.getpid() != parent:
            os.kill(os.getpid(), signal.SIGKILL)
        return "done here"

    parent = os.getpid()
    (value,), _ = run_beside([die_in_child], lambda: None)
    assert value == "done here"


def _in_a_child(job):
    """``job()`` as run by a forked child (this process waits until the child has taken it)."""
    begin, wait = _child_has_begun()
    (value,), _ = run_beside([lambda: begin() or job()], wait)
    return value


def _call(nested: bool):
    """A job whose own run_beside call reports which process ran its one job, and which process it was."""
    import time

    def job():
        if not nested:  # the call runs serially in the child: its one job runs there whatever its own work does
            (ran_in,), _ = run_beside([os.getpid], lambda: time.sleep(0.2), nested=False)
            return ran_in, os.getpid()
        begin, wait = _child_has_begun()  # (a third level runs serially: then no job begins elsewhere)
        (ran_in,), _ = run_beside([lambda: begin() or os.getpid()], lambda: wait(required=False), nested=True)
        return ran_in, os.getpid()

    return job


def test_a_child_forks_again_only_for_a_nested_call_and_only_one_level_down():
    ran_in, child = _in_a_child(_call(nested=False))
    assert child != os.getpid() and ran_in == child  # a child's own calls run serially
    ran_in, child = _in_a_child(_call(nested=True))
    assert len({os.getpid(), child, ran_in}) == 3  # a nested call forks once more
    (ran_in, grandchild), child = _in_a_child(_grandchild_runs(_call(nested=True)))
    assert len({os.getpid(), child, grandchild}) == 3 and ran_in == grandchild  # no third level


def _grandchild_runs(job):
    """A job that has ``job`` run by a grandchild (a nested call from the child); ``(job(), child's pid)``."""

    def run():
        begin, wait = _child_has_begun()
        (value,), _ = run_beside([lambda: begin() or job()], wait, nested=True)
        return value, os.getpid()

    return run


def test_off_means_serial_in_this_process():
    allow_fork(False)
    (pid,), _ = run_beside([os.getpid], lambda: None)
    assert pid == os.getpid()


@pytest.mark.slow
@pytest.mark.parametrize(("spec", "figure"), [("specs/x4_rotor_pi.yaml", "feasible_region.png"),
                                              ("specs/x4_rotor.yaml", "oscillation_onset.png")])
def test_design_outputs_are_the_same_bytes_forked_or_serial(tmp_path: Path, spec: str, figure: str):
    """The design command with SYNTH_JOBS=1 writes every file byte for byte as the default run on two cores does
    (but the command line quoted in the HTML, which names the output folder): x4_rotor_pi is two design jobs
    (with and without integral action), x4_rotor has the report's spec-only studies (onset, gap case) beside the
    design. The same files also say what the committed report says (tests/report_compare.py: it may have been
    written on a machine with another CPU), which keeps it current (tests/test_report.py compares the numbers
    of the others)."""
    from synth.design import design_jobs
    from synth.report.studies import spec_studies
    from synth.spec import load_spec
    from tests.report_compare import same_content

    loaded = load_spec(ROOT / spec)
    assert len(design_jobs(loaded)[0]) + len(spec_studies(loaded)) >= 2
    committed = ROOT / "reports" / Path(spec).stem
    written = {}
    for jobs in ("1", "2"):
        out = tmp_path / f"jobs{jobs}"
        done = subprocess.run([sys.executable, "-m", "synth", "design", spec, "--out", str(out)], cwd=ROOT,
                              env={**os.environ, "SYNTH_JOBS": jobs}, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        names = sorted(p.name for p in out.iterdir() if p.name != ".synth-manifest.json")
        written[jobs] = {name: (out / name).read_bytes().replace(f" --out {out}".encode(), b"") for name in names}
    serial, forked = written["1"], written["2"]
    assert serial.keys() == forked.keys() and figure in serial
    differ = [name for name in serial if serial[name] != forked[name]]
    assert not differ, f"not the same bytes forked and serial: {differ}"
    # the committed folder also holds the tradeoff command's files, which its manifest lists with synth's others
    assert set(serial) <= {p.name for p in committed.iterdir()}
    stale = [name for name in serial if not same_content(name, (committed / name).read_bytes(), serial[name])]
    assert not stale, (f"reports/{committed.name} differs from what `synth design {spec}` writes: {stale}; "
                       f"regenerate it with `synth design {spec} --force` and commit it")


def test_a_worker_of_the_pool_forks_nothing_further():
    """The diagnosis' worker pool (synth.worker_pool.map_jobs) has the cores: a job's own run_beside (the quantizer's
    search in a joint fit) runs serially in the worker, not in a grandchild."""
    import os
    import time

    from synth.worker_pool import map_jobs

    def slow_pid() -> int:  # while this runs, a forked child would take both jobs
        time.sleep(0.3)
        return os.getpid()

    def job(_):
        out, mine = run_beside([os.getpid, os.getpid], slow_pid)
        return set(out) == {mine}

    assert map_jobs(job, [0, 1], workers=2) == [True, True]
    out, mine = run_beside([os.getpid, os.getpid], slow_pid)  # here, forking allowed, the child takes them
    assert mine not in out
