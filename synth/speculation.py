"""Values computed ahead on the idle core: a sequential search that knows its likely next question asks it early.

A bisection or a pattern search evaluates one point at a time, and which point comes next depends on the
answer. While this process computes the value it needs now, a forked helper process can compute the one it
will probably need next (:meth:`Speculator.ahead`); when the search asks for that value
(:meth:`Speculator.value`) it is taken from the helper, or computed here when the guess was wrong. The search
takes exactly the path it takes without the helper, and gives the same answer: the function must be pure (its
value depends on its key alone), which a fork keeps (the helper is a copy of this process at the first
guess).

The helper runs only where :func:`synth.forked.spare_core` says the other core is idle; elsewhere (a library
call, ``SYNTH_JOBS=1``, a job beside another) nothing is forked and :meth:`Speculator.value` computes every
value here. A helper that fails or dies costs nothing but its own work: the value is computed here.
"""

from __future__ import annotations

import os
import pickle
import select
import signal
import struct
from collections.abc import Callable, Hashable
from typing import Any, Generic, TypeVar

from synth import forked, progress

__all__ = ["Speculator"]

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")

_HEADER = struct.Struct("<Q")


class Speculator(Generic[K, V]):
    """``fn(key)`` for a sequential search, with a guess of the next key computed by a helper process meanwhile.

    Use as a context manager (the helper is stopped at its end). One guess is in flight at a time: a guess made
    while the helper still works on an earlier one is dropped.

    Parameters
    ----------
    fn : callable
        A pure function of a hashable key (same key, same value) whose value pickles.

    Examples
    --------
    >>> from synth.forked import allow_fork
    >>> allow_fork(False)  # a library call: nothing is forked
    >>> calls = []
    >>> def square(x):
    ...     calls.append(x)
    ...     return x * x
    >>> with Speculator(square) as spec:  # every value computed here
    ...     spec.ahead(3)
    ...     [spec.value(2), spec.value(3)]
    [4, 9]
    >>> calls
    [2, 3]
    """

    def __init__(self, fn: Callable[[K], V]) -> None:
        self._fn = fn
        self._known: dict[K, V] = {}
        self._pending: K | None = None
        self._pid = 0
        self._requests = -1
        self._answers = -1
        self._spare = False
        self._finished = False  # a helper stopped or failed: no new one
        self.guesses = 0
        """Keys sent to the helper."""
        self.hits = 0
        """Values taken from the helper."""

    def __enter__(self) -> Speculator[K, V]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def ahead(self, key: K) -> None:
        """Let the helper compute ``fn(key)`` if it is idle (starting it on the first call when the other core is
        idle; never again once it stopped or failed); otherwise nothing."""
        if key in self._known or key == self._pending:
            return
        if self._pid == 0:
            if self._finished or not forked.spare_core():
                return
            self._start()
            if self._pid == 0:
                return
        self._collect(block=False)
        if self._pending is not None:
            return
        try:
            _send(self._requests, key)
        except OSError:
            self._stop()
            return
        self._pending = key
        self.guesses += 1

    def expects(self, key: K) -> bool:
        """Whether the helper has computed or is computing ``fn(key)`` (a search then learns its answer without
        computing it, and should guess the step after it only once it knows it).

        Examples
        --------
        >>> from synth.forked import allow_fork
        >>> allow_fork(False)
        >>> with Speculator(abs) as spec:
        ...     spec.ahead(-1); spec.expects(-1)  # no helper in a library call
        False
        """
        return key in self._known or (self._pending is not None and key == self._pending)

    def value(self, key: K) -> V:
        """``fn(key)``: the helper's when it computed or is computing it, else computed here."""
        if self._pending is not None:
            self._collect(block=key == self._pending)
        if key in self._known:
            self.hits += 1
            return self._known.pop(key)
        return self._fn(key)

    def close(self) -> None:
        """Stop the helper (if any); no new one starts."""
        self._stop()

    # ------------------------------------------------------------------ the helper
    def _start(self) -> None:
        request_read, request_write = os.pipe()
        answer_read, answer_write = os.pipe()
        try:
            pid = os.fork()
        except OSError:  # no process to spare (a limit reached): every value computed here
            for fd in (request_read, request_write, answer_read, answer_write):
                os.close(fd)
            self._finished = True
            return
        if pid == 0:  # the helper: answer requests until the pipe closes, never return into the caller
            try:
                os.close(request_write)
                os.close(answer_read)
                forked.become_helper()
                progress.disable()  # the helper's stages are guesses: not shown
                _serve(self._fn, request_read, answer_write)
            finally:
                os._exit(0)
        os.close(request_read)
        os.close(answer_write)
        self._pid, self._requests, self._answers = pid, request_write, answer_read
        self._spare = forked.occupy_spare_core()  # the helper has the other core now

    def _collect(self, block: bool) -> None:
        """Take the helper's answer to the pending key when it is there (waiting for it when ``block``)."""
        if self._pending is None or self._pid == 0:
            self._pending = None
            return
        if not block and not select.select([self._answers], [], [], 0)[0]:
            return
        key, self._pending = self._pending, None
        try:
            kind, value = _receive(self._answers)
        except (OSError, EOFError, pickle.UnpicklingError):
            self._stop()
            return
        if kind == "value":
            self._known[key] = value
        # an exception in the helper: the value is computed here when asked for (raising it here)

    def _stop(self) -> None:
        if self._pid:
            for fd in (self._requests, self._answers):
                try:
                    os.close(fd)
                except OSError:
                    pass
            try:
                os.kill(self._pid, signal.SIGKILL)
                os.waitpid(self._pid, 0)
            except (ChildProcessError, ProcessLookupError):
                pass
            forked.restore_spare_core(self._spare)
        self._pid, self._pending, self._finished = 0, None, True


def _serve(fn: Callable[[Any], Any], requests: int, answers: int) -> None:
    while True:
        try:
            key = _receive(requests)
        except (OSError, EOFError):
            return
        try:
            outcome: tuple[str, Any] = ("value", fn(key))
            payload = pickle.dumps(outcome, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:
            payload = pickle.dumps(("raised", None), protocol=pickle.HIGHEST_PROTOCOL)
        _write_all(answers, _HEADER.pack(len(payload)) + payload)


def _send(fd: int, obj: Any) -> None:
    payload = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    _write_all(fd, _HEADER.pack(len(payload)) + payload)


def _receive(fd: int) -> Any:
    (size,) = _HEADER.unpack(_read_exactly(fd, _HEADER.size))
    return pickle.loads(_read_exactly(fd, size))


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _read_exactly(fd: int, size: int) -> bytes:
    parts, left = [], size
    while left:
        chunk = os.read(fd, min(left, 1 << 20))
        if not chunk:
            raise EOFError("the helper's pipe closed")
        parts.append(chunk)
        left -= len(chunk)
    return b"".join(parts)
