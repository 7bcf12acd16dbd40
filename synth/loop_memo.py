"""A bounded memo of a costly, pure answer about a loop: the searches ask about the same loop again.

A design with a step-response limit checks the same controllers several times over: the bisection on the
surrogate level, the segment towards the first design that failed, the pattern search (whose exploratory
moves come back to points they tried) and the certificate. On a PI behind 20 ms with an overshoot limit,
52 of 161 simulated steps were of a loop simulated before. :class:`LoopMemo` keeps the most recent answers,
keyed by everything the loop's answer depends on: the controller's type and parameters, the plant's
polynomials and delay, and what the caller adds (the requirement asking). The answer must be a pure function
of that key (and immutable: every caller gets the same object).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import TYPE_CHECKING, Generic, TypeVar

if TYPE_CHECKING:
    from synth.loop import Loop

__all__ = ["LoopMemo"]

V = TypeVar("V")


class LoopMemo(Generic[V]):
    """The last ``size`` answers of ``compute(loop)``, by :meth:`key`.

    Parameters
    ----------
    size : int
        Answers kept (the least recently used one is dropped first).

    Examples
    --------
    >>> from synth.loop import Loop
    >>> memo, calls = LoopMemo(size=2), []
    >>> def poles(loop):
    ...     calls.append(1)
    ...     return loop.closed_loop_poles()
    >>> a = memo.get(Loop("1/(s+1)", "P(2)"), poles)
    >>> b = memo.get(Loop("1/(s+1)", "P(2.0)"), poles)  # the same loop: not computed again
    >>> a is b, len(calls), memo.get(Loop("1/(s+1)", "P(2)"), poles, "other caller") is a, len(calls)
    (True, 1, False, 2)
    """

    def __init__(self, size: int = 256) -> None:
        self.size = size
        self._values: OrderedDict[Hashable, V] = OrderedDict()

    @staticmethod
    def key(loop: Loop, *extra: Hashable) -> Hashable:
        """What a loop's answer depends on: ``extra``, the controller's type and parameter values, the plant's
        numerator, denominator and delay.

        Examples
        --------
        >>> from synth.loop import Loop
        >>> LoopMemo.key(Loop("1/(s+1)", "PI(1, 2)")) == LoopMemo.key(Loop("1/(s+1)", "PI(kp=1.0, ki=2.0)"))
        True
        """
        c, p = loop.controller, loop.plant
        return (*extra, c.type, tuple(c.parameters.values()), p.num.tobytes(), p.den.tobytes(), float(p.delay))

    def get(self, loop: Loop, compute: Callable[[Loop], V], *extra: Hashable) -> V:
        """``compute(loop)``, or the answer kept for the same :meth:`key` (``extra`` included)."""
        key = self.key(loop, *extra)
        if key in self._values:
            self._values.move_to_end(key)
            return self._values[key]
        value = compute(loop)
        self._values[key] = value
        if len(self._values) > self.size:
            self._values.popitem(last=False)
        return value
