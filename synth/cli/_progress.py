"""A live line on the terminal for a command whose length is not known in advance (``synth design``).

The computation announces its stages with :func:`synth.progress.announce`, in this process or in a forked
child; a thread here redraws one line on standard error with the stages and the elapsed time. Runs shorter
than :data:`DELAY` draw nothing, and nothing is drawn when standard error is not a terminal.
"""

from __future__ import annotations

import shutil
import sys
import threading
import time
from typing import Any, TextIO

from synth.progress import current, disable, enable

__all__ = ["DELAY", "StageLine"]

DELAY = 2.0
"""Seconds before the line appears: a short run stays quiet."""


class StageLine:
    """Within the block, show ``label: <stages> [elapsed]`` on ``stream`` (standard error by default).

    Examples
    --------
    >>> import io
    >>> from synth.progress import announce
    >>> out = io.StringIO()
    >>> with StageLine("design", enabled=True, stream=out, delay=0.0, interval=0.01):
    ...     announce("convex stage"); time.sleep(0.1)
    >>> "design: convex stage [" in out.getvalue()
    True
    """

    def __init__(self, label: str, enabled: bool | None = None, stream: TextIO | None = None,
                 delay: float | None = None, interval: float = 0.5) -> None:
        self.stream = stream or sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.label, self.delay, self.interval = label, DELAY if delay is None else delay, interval
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
