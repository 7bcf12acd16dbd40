"""A pool of worker processes that die with the command and stop at once when it is interrupted.

:func:`map_jobs` runs independent jobs on several processes (``synth diagnose``'s joint re-fits, ``synth
tradeoff``'s chunks). Each worker first runs :func:`watch_parent`, so a SIGKILL or SIGTERM of the command leaves
no worker behind; an exception in the command (a KeyboardInterrupt or the exception a signal handler raises)
terminates the workers before it propagates.
"""

from __future__ import annotations

from typing import Any

__all__ = ["map_jobs", "watch_parent"]


def watch_parent(parent: int) -> None:
    """Make this (worker) process die with its parent ``parent``; leave signals to the parent.

    On Linux the kernel sends SIGKILL when the parent dies (``prctl(PR_SET_PDEATHSIG)``, even when the
    parent is killed by SIGKILL); elsewhere a daemon thread checks the parent's pid every second. SIGINT
    is ignored (a Ctrl-C reaches the whole process group: the parent handles it and terminates the
    workers) and SIGTERM has its default action. A worker forks nothing further (:func:`synth.forked.become_helper`).

    Examples
    --------
    It runs first in every worker of :func:`map_jobs`:

    >>> map_jobs(abs, [-1, -2], workers=2)
    [1, 2]
    """
    import os
    import signal
    import sys
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    from synth.forked import become_helper

    become_helper()  # the pool has the cores: a job's own run_beside (the quantizer's search) runs here, serially
    armed = False
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(1, int(signal.SIGKILL), 0, 0, 0) == 0  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):
            armed = False
    if os.getppid() != parent:  # the parent died before the watch was set
        os._exit(1)
    if armed:
        return

    def check() -> None:
        import time

        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=check, daemon=True).start()


def map_jobs(fn: Any, jobs: list[Any], workers: int, done: Any = None) -> list[Any]:
    """``[fn(j) for j in jobs]``, on ``workers`` processes when there are several jobs.

    ``done(i)``, if given, is called in this process as job ``i`` finishes (in order). On Linux the workers
    are forked and inherit ``fn`` and the jobs (only indices go through the pool's pipe); elsewhere ``fn`` and
    the jobs must pickle.

    The workers die with this process (:func:`watch_parent`: a SIGKILL of the parent leaves none
    behind), and any exception here, a KeyboardInterrupt or the exception a signal handler raises
    included, terminates them before it propagates.

    Examples
    --------
    >>> map_jobs(abs, [-1, 2, -3], workers=1)
    [1, 2, 3]
    """
    if workers <= 1 or len(jobs) <= 1:
        out = []
        for i, j in enumerate(jobs):
            out.append(fn(j))
            if done is not None:
                done(i)
        return out
    import multiprocessing
    import os
    import sys

    # on Linux the workers are forked and inherit the jobs; elsewhere the platform's default start method
    # pickles them (macOS's default, spawn: fork is unsafe there with some system libraries)
    forked = sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if forked else None)
    if forked:  # the workers inherit the jobs: only their indices go through the task pipe (see _inherited_job)
        _INHERITED[:] = [fn, jobs]
        fn, jobs = _inherited_job, list(range(len(jobs)))
    pool = context.Pool(min(workers, len(jobs)), initializer=watch_parent, initargs=(os.getpid(),))
    try:
        out = []
        for i, res in enumerate(pool.imap(fn, jobs, chunksize=1)):
            out.append(res)
            if done is not None:
                done(i)
        pool.close()
        return out
    except BaseException:
        pool.terminate()
        raise
    finally:
        pool.join()
        _INHERITED.clear()


_INHERITED: list[Any] = []  # the function and jobs of the running map_jobs, inherited by its forked workers


def _inherited_job(index: int) -> Any:
    """Run job ``index`` of the :func:`map_jobs` call that forked this worker.

    Sending the jobs themselves (records of hundreds of thousands of samples) through the pool's task pipe
    filled it: the pool's task thread then blocked on a write that no terminated worker would read, and
    ``Pool.terminate`` waited for that thread forever (a SIGTERM during the attribution hung ``synth
    diagnose``). An index never fills the pipe.

    Examples
    --------
    >>> _INHERITED[:] = [abs, [-4]]
    >>> _inherited_job(0)
    4
    >>> _INHERITED.clear()
    """
    fn, jobs = _INHERITED
    return fn(jobs[index])
