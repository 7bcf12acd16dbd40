"""The command line keeps the libraries' numerical warnings off the user's terminal (a PID design on an
unstable delayed plant printed cvxpy's "Solution may be inaccurate" and numpy's overflow warnings from trial
designs above its verdict); ``python -W`` (``sys.warnoptions``) shows them again."""

import sys
import warnings

import pytest

import synth.cli.check as check_command
from synth.cli import main


@pytest.fixture
def warning_check(monkeypatch):
    real = check_command.run

    def run(args):
        warnings.warn("overflow encountered in scalar multiply", RuntimeWarning, stacklevel=2)
        return real(args)

    monkeypatch.setattr(check_command, "run", run)


def _run_check():
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        code = main(["check", "specs/x4_rotor.yaml", "--controller", "P(3)", "--quiet"])
    return code, [str(w.message) for w in seen]


def test_library_warnings_stay_off_the_terminal(warning_check, monkeypatch):
    monkeypatch.setattr(sys, "warnoptions", [])
    code, seen = _run_check()
    assert code == 0 and seen == []


def test_python_w_shows_them(warning_check, monkeypatch):
    monkeypatch.setattr(sys, "warnoptions", ["default"])
    code, seen = _run_check()
    assert code == 0 and seen == ["overflow encountered in scalar multiply"]
