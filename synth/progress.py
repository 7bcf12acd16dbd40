"""What a long computation is doing now, readable by the command line while it runs, across forked jobs.

A design can run for minutes in a forked child (:mod:`synth.forked`) while the command's own process waits.
Stages announce themselves with :func:`announce`; the text lands in a small block of shared memory that the
command line's progress display reads (:func:`current`). Each process writes its own slot: the parent's is
0, a forked child's is 1 (:func:`use_child_slot`, called by :func:`synth.forked.run_beside` in the child).
Nothing is shared or written until :func:`enable` made the block (the command line does, through
:class:`StageLine`, which redraws one line on a terminal's standard error with the stages and the elapsed time);
a library caller pays one ``None`` check per stage.
"""

from __future__ import annotations

import mmap
import shutil
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, TextIO

__all__ = ["DELAY", "INTERVAL", "WIDTH", "StageLine", "announce", "clear", "current", "disable", "enable",
           "use_child_slot", "within"]

SLOTS = 2
"""One slot for the command's process, one for its forked child."""

WIDTH = 200
"""Bytes per slot: a stage's text is cut to fit (UTF-8, at a character boundary)."""

_BOARD: list[mmap.mmap | None] = [None]
_SLOT = [0]
_WITHIN: list[str] = []


def enable() -> None:
    """Make the shared block (before any fork, so that forked children write into the same memory).

    Examples
    --------
    >>> enable(); announce("convex stage"); current()
    ['convex stage']
    >>> disable(); announce("not recorded"); current()
    []
    """
    if _BOARD[0] is None:
        _BOARD[0] = mmap.mmap(-1, SLOTS * WIDTH)  # anonymous and shared: a fork's child sees the same bytes
    _BOARD[0][:] = bytes(SLOTS * WIDTH)


def disable() -> None:
    """Stop recording stages (the block is dropped)."""
    board, _BOARD[0] = _BOARD[0], None
    if board is not None:
        board.close()


def use_child_slot() -> None:
    """In a forked child: write to the child's slot from now on."""
    _SLOT[0] = 1


def announce(text: str) -> None:
    """Record what this process is doing now (no effect unless :func:`enable` was called).

    Examples
    --------
    >>> enable(); announce("NLP polish (IPOPT)"); announce("certificate"); current()
    ['certificate']
    >>> disable()
    """
    board = _BOARD[0]
    if board is None:
        return
    data = " > ".join([*_WITHIN, text]).encode("utf-8")[:WIDTH].decode("utf-8", "ignore").encode("utf-8")
    start = _SLOT[0] * WIDTH
    board[start:start + WIDTH] = data + bytes(WIDTH - len(data))


@contextmanager
def within(text: str) -> Iterator[None]:
    """Within the block, every announced stage is shown as a step of ``text`` (``text > stage``).

    Examples
    --------
    >>> enable()
    >>> with within("outer loop, design 2"):
    ...     announce("NLP polish")
    ...     current()
    ['outer loop, design 2 > NLP polish']
    >>> disable()
    """
    _WITHIN.append(text)
    announce("starting")
    try:
        yield
    finally:
        _WITHIN.pop()


def clear() -> None:
    """Empty this process's slot (a forked child that finished its jobs: its last stage is no longer news).

    Examples
    --------
    >>> enable(); announce("NLP polish"); clear(); current()
    []
    >>> disable()
    """
    board = _BOARD[0]
    if board is not None:
        board[_SLOT[0] * WIDTH:(_SLOT[0] + 1) * WIDTH] = bytes(WIDTH)


def current() -> list[str]:
    """The stages recorded, one per process that recorded one (the command's first).

    Examples
    --------
    >>> current()  # not enabled
    []
    """
    board = _BOARD[0]
    if board is None:
        return []
    texts = (board[i * WIDTH:(i + 1) * WIDTH].rstrip(b"\0").decode("utf-8", "ignore") for i in range(SLOTS))
    return [t for t in texts if t]


DELAY = 2.0
"""Seconds before the line appears: a short run stays quiet."""

INTERVAL = 0.5
"""Seconds between redraws of the line."""


class StageLine:
    """Within the block, show ``label: <stages> [elapsed]`` on ``stream`` (standard error by default).

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> with StageLine("design", enabled=True, stream=out, delay=0.0, interval=0.01):
    ...     announce("convex stage"); time.sleep(0.1)
    >>> "design: convex stage [" in out.getvalue()
    True
    """

    def __init__(self, label: str, enabled: bool | None = None, stream: TextIO | None = None,
                 delay: float | None = None, interval: float | None = None) -> None:
        self.stream = stream or sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.label, self.delay = label, DELAY if delay is None else delay
        self.interval = INTERVAL if interval is None else interval
        self.stop = threading.Event()
        self.width = 0

    def __enter__(self) -> StageLine:
        if self.enabled:
            enable()  # before any fork: the children write into the same block
            self.t0 = time.monotonic()
            self.thread = threading.Thread(target=self._draw, daemon=True)
            self.thread.start()
        return self

    def _draw(self) -> None:
        if self.stop.wait(self.delay):
            return
        while True:
            elapsed = int(time.monotonic() - self.t0)
            clock = f" [{elapsed // 60}:{elapsed % 60:02d}]"
            room = shutil.get_terminal_size().columns - 1 - len(clock)
            line = f"{self.label}: {' | '.join(current()) or 'starting'}"
            if len(line) > room:  # the innermost stage is the news: cut the front
                line = "..." + line[len(line) - room + 3:]
            line += clock
            self.stream.write("\r" + line.ljust(self.width))
            self.stream.flush()
            self.width = max(self.width, len(line))
            if self.stop.wait(self.interval):
                return

    def __exit__(self, *exc: Any) -> None:
        if not self.enabled:
            return
        self.stop.set()
        self.thread.join()
        if self.width:
            self.stream.write("\r" + " " * self.width + "\r")  # the line goes away: the verdict follows
            self.stream.flush()
        disable()
