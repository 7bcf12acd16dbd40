"""``synth design`` shows what it is doing while it runs (a live line on a terminal's standard error).

A multi-parameter design can run for minutes in a forked child; before, the terminal stayed blank until the
verdict. The stages are announced through shared memory (:mod:`synth.progress`), so the line also shows the
child's stage, and it is cleared before the verdict is printed.
"""

import io
import time

from synth import progress
from synth.cli import main
from synth.forked import allow_fork, run_beside


def test_a_forked_childs_stage_is_seen_by_the_parent(monkeypatch):
    monkeypatch.delenv("SYNTH_JOBS", raising=False)  # conftest turns forking off for the rest of the suite
    progress.enable()
    allow_fork(True)
    try:
        def child() -> int:
            progress.announce("child at work")
            time.sleep(1.0)
            return 1

        def parent() -> list[str]:
            deadline = time.monotonic() + 60.0  # the child may start late on a loaded machine
            while time.monotonic() < deadline and "child at work" not in progress.current():
                time.sleep(0.01)
            return progress.current()

        (value,), seen = run_beside([child], parent)
        after = progress.current()
    finally:
        allow_fork(False)
        progress.disable()
    assert value == 1 and "child at work" in seen
    assert after == []  # the finished child's stage is cleared


def test_nested_stages_and_nothing_recorded_when_disabled():
    progress.announce("ignored")
    assert progress.current() == []
    progress.enable()
    try:
        with progress.within("outer loop 2/9"):
            with progress.within("without integral action"):
                progress.announce("NLP polish")
                assert progress.current() == ["outer loop 2/9 > without integral action > NLP polish"]
        progress.announce("x" * 500)
        assert len(progress.current()[0].encode()) == progress.WIDTH
    finally:
        progress.disable()


def _terminal_stderr(monkeypatch) -> io.StringIO:
    """Standard error that says it is a terminal, and a line that appears at once (set in the test body:
    pytest's capture re-takes the streams after fixtures run)."""
    stream = io.StringIO()
    stream.isatty = lambda: True  # type: ignore[method-assign]
    monkeypatch.setattr("sys.stderr", stream)
    monkeypatch.setattr(progress, "DELAY", 0.0)
    monkeypatch.setattr(progress, "INTERVAL", 0.002)  # a warm worker designs the PI in a few tenths of a second
    return stream


def test_design_shows_its_stages_on_a_terminal_and_clears_the_line(tmp_path, monkeypatch, capsys):
    terminal_stderr = _terminal_stderr(monkeypatch)
    spec = tmp_path / "pi.yaml"  # the convex stage alone (its answer is a KKT point: no polish), about 2 s
    spec.write_text("name: pi\nplant: {tf: \"23*(s+0.43)/((s+9.6)*(s+0.54))\", delay: 0.02}\ncontroller: {type: PI, "
                    "bounds: {kp: [0, 10], ki: [1, 200]}}\nrequirements:\n  - {type: peak_sensitivity, max_db: 6}\n"
                    "objective: {maximize: integral_gain}\n", encoding="utf-8")
    code = main(["design", str(spec), "--no-report"])
    shown = terminal_stderr.getvalue()
    assert code == 0
    assert "\rdesign: convex stage [0:" in shown
    assert shown.endswith("\r")  # the last write blanks the line before the verdict
    assert "pi: FEASIBLE" in capsys.readouterr().out
    assert progress.current() == []  # the block is gone after the command


def test_quiet_design_draws_nothing(tmp_path, monkeypatch):
    terminal_stderr = _terminal_stderr(monkeypatch)
    spec = tmp_path / "p.yaml"
    spec.write_text("name: p\nplant: {tf: \"1/(s+1)\"}\ncontroller: {type: PI}\nrequirements:\n"
                    "  - {type: peak_sensitivity, max_db: 6}\n", encoding="utf-8")
    assert main(["design", str(spec), "--no-report", "--quiet"]) == 0
    assert terminal_stderr.getvalue() == ""
