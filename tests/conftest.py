"""Test helpers: the shared data folder, and running the CLI in-process."""

from __future__ import annotations

import io
import os
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

# One BLAS thread per process: the suite runs one pytest worker per core (xdist), and OpenBLAS's own threads in
# each worker would compete with the other worker for the same cores (set before anything imports numpy; the
# workers and the commands the tests start inherit it).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# The same for synth's own helper process: a command computes ahead on the other core only when that core is idle
# (synth.forked, synth.speculation), which under xdist it is not; the guesses it would compute there cost the other
# worker's time. The tests of forking itself unset this (tests/test_forked.py, test_speculation.py,
# test_cli_design_progress.py); test_forked.py also checks that a forked command writes the same bytes.
os.environ.setdefault("SYNTH_JOBS", "1")

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("SYNTH_SHARED", ROOT.parent / "shared"))
X4_PLANT = "23*(s+0.43)/((s+9.6)*(s+0.54))"


def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config, items: list[pytest.Item]) -> None:
    """Tests marked ``slow`` first (a stable sort, so the rest keep their order): the workers take tests in this
    order, and the longest started last kept one core busy while the other had finished (pyproject's marker)."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


def shared_path(*parts: str) -> Path:
    """Path inside ../shared, skipping the test with a clear reason if it is absent."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"needs the shared data folder {path} (present in CI and the dev workspace, "
                    "absent in a plain clone); set SYNTH_SHARED to point elsewhere")
    return path


class CliResult:
    def __init__(self, code: int, out: str, err: str) -> None:
        self.code, self.out, self.err = code, out, err


@pytest.fixture
def run_cli():
    """Run ``synth ARGS`` in-process; returns exit code, stdout, stderr."""
    from synth.cli import main

    def run(*args: str) -> CliResult:
        out, err = io.StringIO(), io.StringIO()
        with redirect_stdout(out), redirect_stderr(err):
            try:
                code = main(list(args))
            except SystemExit as exc:  # argparse
                code = int(exc.code or 0)
        return CliResult(code, out.getvalue(), err.getvalue())

    return run
