"""The one place that imports numba.

The simulation loop is sequential (each step feeds the next through
nonlinear blocks), so numpy cannot vectorize it over time; numba compiles it
to machine code (about 100 times faster than a Python loop, see
``benchmarks/sim_speed.py``). Compiled code is cached on disk next to the
sources. Without numba the same functions run as plain Python (correct, slow).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["HAVE_NUMBA", "jit"]

try:  # pragma: no cover - exercised implicitly
    from numba import njit as _njit

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    HAVE_NUMBA = False
    _njit = None


def jit(func: Callable[..., Any]) -> Callable[..., Any]:
    """Compile ``func`` with ``numba.njit(cache=True)`` when numba is installed.

    Examples
    --------
    >>> @jit
    ... def twice(x):
    ...     return 2.0 * x
    >>> twice(1.5)
    3.0
    """
    if _njit is None:  # pragma: no cover
        return func
    try:
        return _njit(cache=True)(func)
    except RuntimeError:  # no file to cache next to (interactive or doctest code)
        return _njit(func)
