"""Two cores for one command: independent jobs (a design, figures) run in one forked child process while
this process goes on with its own work; the jobs' results come back pickled through a pipe.

Forking is off unless :func:`allow_fork` turned it on (the command line does; a library caller's threads or
event loop are its own business), and ``SYNTH_JOBS=1`` turns it off again. A forked child runs its jobs' own
``run_beside`` calls serially, except a call that passes ``nested=True``: a long job whose parts are independent
(the pattern searches of a search of the bounds) forks once more there, for the core that the command's own
process leaves idle once its part is done (at most one level: a grandchild never forks).

A process that knows the other core is idle may also keep a helper there (:func:`spare_core`, used by
:class:`synth.speculation.Speculator`): the command's own process while nothing else of the command runs, and a
child whose parent lent it the core (``run_beside(..., lend_core=True)``: the parent's own work is short and
no job is left for it).

Correctness never depends on the child: off Linux (macOS's system libraries are not safe to use in a forked
child) or when it is off, the jobs run here, in order; an exception a job raised in the child is raised
here; a job whose result or exception does not survive pickling, or every job of a child that died, runs
here again. The child dies with its parent
(``PR_SET_PDEATHSIG`` on Linux) and never returns into the caller: it leaves through ``os._exit``.
"""

from __future__ import annotations

import os
import pickle
import signal
import sys
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from synth.progress import clear, use_child_slot

__all__ = ["allow_fork", "become_helper", "fork_allowed", "occupy_spare_core", "restore_spare_core", "run_beside",
           "spare_core"]

T = TypeVar("T")

_ALLOWED = [False]
_DEPTH = [0]  # 0 in the process that allowed forking, 1 in its child, 2 in a nested call's child
_SPARE = [True]  # whether the other core is idle while this process works (see spare_core)


def allow_fork(allowed: bool = True) -> None:
    """Let :func:`run_beside` use a forked child (off by default; ``SYNTH_JOBS=1`` keeps it off).

    Examples
    --------
    >>> allow_fork(False); run_beside([lambda: 1], lambda: 2)
    ([1], 2)
    """
    _ALLOWED[0] = allowed


def fork_allowed() -> bool:
    """Whether this process may fork at all: :func:`allow_fork` called, on Linux, ``SYNTH_JOBS`` not 1.

    Examples
    --------
    >>> allow_fork(False); fork_allowed()
    False
    """
    return _ALLOWED[0] and sys.platform.startswith("linux") and os.environ.get("SYNTH_JOBS", "") != "1"


def spare_core() -> bool:
    """Whether a helper process may use the other core now: forking is allowed, and no forked job of this command
    is running beside this process (in the command's process outside :func:`run_beside`; in a child only when
    its parent lent it the core, and not while the child's own nested call runs).

    Examples
    --------
    >>> allow_fork(False); spare_core()
    False
    """
    return fork_allowed() and _SPARE[0] and _DEPTH[0] <= 1


def occupy_spare_core() -> bool:
    """Mark the other core as taken (a helper was started there); returns what :func:`restore_spare_core` needs.

    Examples
    --------
    >>> allow_fork(); before = occupy_spare_core(); spare_core()
    False
    >>> restore_spare_core(before); spare_core() == (before and fork_allowed())  # SYNTH_JOBS=1 keeps it off
    True
    """
    before, _SPARE[0] = _SPARE[0], False
    return before


def restore_spare_core(before: bool) -> None:
    """Undo :func:`occupy_spare_core` (the helper has stopped)."""
    _SPARE[0] = before


def become_helper() -> None:
    """In a freshly forked helper process (:class:`synth.speculation.Speculator`): die with the parent, fork
    nothing further, use no spare core."""
    _die_with_parent()
    _DEPTH[0] = 2
    _SPARE[0] = False


def run_beside(jobs: Sequence[Callable[[], Any]], own_work: Callable[[], T], nested: bool = False,
               lend_core: bool = False) -> tuple[list[Any], T]:
    """Run ``jobs`` in a forked child while ``own_work()`` runs here; return both results.

    The child takes the jobs in order; when ``own_work`` is done this process takes the ones the child has
    not started (one ticket per job in a pipe, read one byte at a time by either process), so the two
    cores stay busy whichever side has more to do.

    Parameters
    ----------
    jobs : sequence of callables without arguments (at most 255)
        Independent of ``own_work`` and of each other's side effects here (a child's changes to this
        process's objects are lost: only return values come back, so they must pickle).
    own_work : callable without arguments
        What this process does meanwhile.
    nested : bool
        Fork even in a forked child (one level down, not further): for independent parts of one long job.
    lend_core : bool
        ``own_work`` is short and no job will be left for this process: the child may keep a helper on this
        process's core once it is idle (:func:`spare_core`).

    Returns
    -------
    (list, object)
        The jobs' return values in order, and ``own_work()``'s.

    Examples
    --------
    >>> allow_fork(); run_beside([lambda: 2 + 2, lambda: "x" * 3], lambda: 10)
    ([4, 'xxx'], 10)
    """
    depth_ok = _DEPTH[0] == 0 or (nested and _DEPTH[0] == 1)
    if len(jobs) == 0 or len(jobs) > 255 or not depth_ok or not fork_allowed():  # fork is safe on Linux only
        mine = own_work()
        return [job() for job in jobs], mine
    tickets_read, tickets_write = os.pipe()
    os.write(tickets_write, bytes(range(len(jobs))))  # < PIPE_BUF: one atomic write, never blocks
    os.close(tickets_write)
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: run jobs while tickets last, send the results, leave without returning
        status = 1
        try:
            os.close(read_end)
            _die_with_parent()
            _DEPTH[0] += 1  # two cores: a job's own run_beside calls run serially in the child, unless nested
            _SPARE[0] = lend_core
            use_child_slot()  # the stages this child announces show beside the parent's
            payload = pickle.dumps(_run_tickets(jobs, tickets_read), protocol=pickle.HIGHEST_PROTOCOL)
            clear()  # the progress line stops showing this child's last stage
            with os.fdopen(write_end, "wb") as pipe:
                pipe.write(payload)
            status = 0
        finally:
            os._exit(status)
    os.close(write_end)
    here: dict[int, Any] = {}
    spare, _SPARE[0] = _SPARE[0], False  # the child works on the other core
    try:
        mine = own_work()
        while ticket := os.read(tickets_read, 1):  # the jobs the child has not started yet
            here[ticket[0]] = jobs[ticket[0]]()
        with os.fdopen(read_end, "rb") as pipe:
            payload = pipe.read()
    except BaseException:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        raise
    finally:
        os.close(tickets_read)
        _SPARE[0] = spare
    _, status = os.waitpid(pid, 0)
    there = (_unpickle(payload) if status == 0 else None) or {}
    out = []
    for i, job in enumerate(jobs):
        if i in here:
            out.append(here[i])
        else:  # the child's result; a job of a child that died runs here
            out.append(_result(job, there.get(i, ("rerun", None))))
    return out, mine


def _run_tickets(jobs: Sequence[Callable[[], Any]], tickets: int) -> dict[int, tuple[str, Any]]:
    """Each job the child took: ``("value", result)``, ``("raised", exception)`` or ``("rerun", None)`` (its
    result or exception does not survive pickling: the parent runs it again)."""
    out: dict[int, tuple[str, Any]] = {}
    while ticket := os.read(tickets, 1):
        job = jobs[ticket[0]]
        try:
            outcome: tuple[str, Any] = ("value", job())
        except Exception as exc:
            outcome = ("raised", exc)
        try:
            pickle.loads(pickle.dumps(outcome))
        except Exception:
            outcome = ("rerun", None)
        out[ticket[0]] = outcome
    return out


def _result(job: Callable[[], Any], outcome: tuple[str, Any]) -> Any:
    kind, value = outcome
    if kind == "value":
        return value
    if kind == "raised":
        raise value
    return job()


def _unpickle(payload: bytes) -> dict[int, tuple[str, Any]] | None:
    try:
        return pickle.loads(payload)
    except Exception:
        return None


def _die_with_parent() -> None:
    """Ask Linux to kill this process when its parent dies (no effect elsewhere)."""
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        pass
