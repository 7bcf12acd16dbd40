"""synth.speculation.Speculator and the searches that guess ahead with it: a guess is computed by a helper process
on the spare core, and the search takes exactly the path (and gives exactly the answer) it takes without one.

The references here are the same searches with no helper (forking off), and plain counts of which points a
search evaluates: a guess that is not the search's next point makes no hit."""

from __future__ import annotations

import os
import select
import time

import numpy as np
import pytest

from synth.forked import allow_fork, run_beside, spare_core
from synth.search import hooke_jeeves
from synth.speculation import Speculator


@pytest.fixture(autouse=True)
def _fork_allowed(monkeypatch):
    monkeypatch.delenv("SYNTH_JOBS", raising=False)
    allow_fork(True)
    yield
    allow_fork(False)


def _square_and_pid(x: int) -> tuple[int, int]:
    time.sleep(0.02)
    return x * x, os.getpid()


def test_a_guess_is_computed_by_the_helper_and_a_wrong_one_changes_nothing():
    with Speculator(_square_and_pid) as guesses:
        guesses.ahead(3)
        here = guesses.value(2)  # computed here while the helper computes 3
        ahead = guesses.value(3)
        guesses.ahead(10)  # a wrong guess: the search asks for 4
        wrong = guesses.value(4)
    assert (here[0], ahead[0], wrong[0]) == (4, 9, 16)
    assert here[1] == os.getpid() and wrong[1] == os.getpid()
    assert ahead[1] != os.getpid()  # the helper's
    assert guesses.hits >= 1 and guesses.guesses == 2


def test_the_helper_is_gone_after_the_block_and_no_new_one_starts():
    with Speculator(_square_and_pid) as guesses:
        guesses.ahead(1)
        helper = guesses.value(1)[1]
    assert helper != os.getpid()
    with pytest.raises(ChildProcessError):
        os.waitpid(helper, os.WNOHANG)  # reaped: no longer a child of this process
    guesses.ahead(5)
    assert not guesses.expects(5) and guesses.value(5) == (25, os.getpid())


def test_an_exception_in_the_helper_is_raised_here_when_the_value_is_asked_for():
    def half(x: int) -> float:
        if x == 0:
            raise ZeroDivisionError("x is 0")
        return 1 / x

    with Speculator(half) as guesses:
        guesses.ahead(0)
        with pytest.raises(ZeroDivisionError, match="x is 0"):
            guesses.value(0)
        assert guesses.value(4) == 0.25


@pytest.mark.parametrize("off", ["allow_fork(False)", "SYNTH_JOBS=1", "beside a forked job"])
def test_nothing_is_forked_without_a_spare_core(off, monkeypatch):
    if off == "allow_fork(False)":
        allow_fork(False)
    elif off == "SYNTH_JOBS=1":
        monkeypatch.setenv("SYNTH_JOBS", "1")

    def search() -> list[int]:
        with Speculator(_square_and_pid) as guesses:
            guesses.ahead(7)
            return [guesses.value(7)[1], guesses.guesses]

    if off == "beside a forked job":
        _, (pid, sent) = run_beside([lambda: time.sleep(0.05)], search)
    else:
        pid, sent = search()
    assert pid == os.getpid() and sent == 0


def test_spare_core_follows_the_jobs_beside():
    assert spare_core()  # the command's process, nothing beside it
    seen = {}

    read_end, write_end = os.pipe()

    def own():
        seen["own"] = spare_core()
        select.select([read_end], [], [], 60.0)  # until the child has taken the job (not a fixed sleep: a loaded
        # machine may start the child late, and this process would take the job itself)

    lent, _ = run_beside([lambda: os.write(write_end, b"x") and spare_core()], own, lend_core=True)
    seen["lent"] = lent[0]
    not_lent, _ = run_beside([lambda: spare_core()], lambda: time.sleep(0.05))
    assert seen == {"own": False, "lent": True} and not_lent == [False]
    assert spare_core()  # restored after the call


def _ridge(z: np.ndarray) -> float:
    return float((z[0] - 1.3) ** 2 + 8.0 * (z[1] - 0.7 * z[0]) ** 2 + 0.5 * abs(z[2] + 0.2))


def _evaluations(ahead: bool, seed: int) -> tuple[list, list, object]:
    rng = np.random.default_rng(seed)
    z0 = rng.uniform(-2, 2, 3)
    seen: list[tuple[float, ...]] = []
    guessed: list[tuple[int, tuple[float, ...]]] = []  # (evaluations made when guessing, the guess)

    def f(z: np.ndarray) -> float:
        seen.append(tuple(z))
        return _ridge(z)

    found = hooke_jeeves(f, z0, np.full(3, -3.0), np.full(3, 3.0), lambda a, b: a < b - 1e-12, 0.4, 1e-5, 300,
                         ahead=(lambda z: guessed.append((len(seen), tuple(z)))) if ahead else None)
    return seen, guessed, found


@pytest.mark.parametrize("seed", range(5))
def test_hooke_jeeves_takes_the_same_path_when_told_to_guess(seed):
    seen, guessed, found = _evaluations(True, seed)
    plain, _, reference = _evaluations(False, seed)
    assert seen == plain and np.array_equal(found.z, reference.z) and found.evaluations == reference.evaluations
    # a guess made before evaluation n names evaluation n + 1 (the move down after the move up, the first move
    # around a pattern's point) or, when the move up helped, none; most of them are taken
    taken = sum(n + 1 < len(seen) and seen[n + 1] == g for n, g in guessed)
    assert guessed and taken / len(guessed) > 0.5


def test_a_pattern_search_and_a_certified_design_are_the_same_with_the_helper():
    """The surrogate's bisection and the pattern search guess ahead on the spare core: same design, same checks,
    and some of the guesses were taken (a PI with an overshoot limit, the docstring's example of
    design_certified)."""
    from synth.spec import parse_spec
    from synth.synthesis import pattern, surrogate
    from synth.synthesis.multi import design_convex

    spec = parse_spec({"name": "os", "plant": {"tf": "2/((s+1)*(s+2))"},
                       "controller": {"type": "PI", "bounds": {"kp": [0.01, 5], "ki": [0, 10]}},
                       "requirements": [{"type": "step_response", "max_overshoot": 10}],
                       "objective": {"maximize": "integral_gain"}})
    hits: list[int] = []

    class Counted(Speculator):
        def close(self) -> None:
            hits.append(self.hits)
            super().close()

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(pattern, "Speculator", Counted)
        mp.setattr(surrogate, "Speculator", Counted)
        guessing = surrogate.design_certified(spec, design_convex)
    allow_fork(False)
    serial = surrogate.design_certified(spec, design_convex)
    assert guessing.controller.parameters == serial.controller.parameters
    assert guessing.method == serial.method and guessing.extras["surrogate"] == serial.extras["surrogate"]
    assert guessing.feasible and len(hits) == 2 and min(hits) > 0  # the bisection's guesses, the search's


def test_a_helper_that_dies_costs_only_its_guess():
    import signal

    with Speculator(_square_and_pid) as guesses:
        guesses.ahead(3)
        assert guesses.expects(3)
        os.kill(guesses._pid, signal.SIGKILL)  # the helper process
        assert guesses.value(3) == (9, os.getpid())  # computed here
        guesses.ahead(4)  # no helper any more: nothing is sent
        assert not guesses.expects(4) and guesses.value(4) == (16, os.getpid())


def test_a_fork_that_fails_leaves_every_value_to_this_process(monkeypatch):
    import synth.speculation as speculation

    def no_fork() -> int:
        raise OSError("Resource temporarily unavailable")

    monkeypatch.setattr(speculation.os, "fork", no_fork)
    with Speculator(_square_and_pid) as guesses:
        guesses.ahead(2)
        assert not guesses.expects(2) and guesses.value(2) == (4, os.getpid()) and guesses.guesses == 0
