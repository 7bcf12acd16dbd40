"""The one place that imports numba.

The simulation loop is sequential (each step feeds the next through
nonlinear blocks), so numpy cannot vectorize it over time; numba compiles it
to machine code (about 100 times faster than a Python loop, see
``benchmarks/sim_speed.py``). Compiled code is cached on disk next to the
sources. Without numba the same functions run as plain Python (correct, slow).

numba's cache notices a change to the file a function is defined in, not to the files of the functions it
calls (the block equations the loop kernel inlines) or of the constants it reads: here every cached
function's entry is also stamped with the size and time of every module in its own package, so an edited
or upgraded block is never run from an old compilation.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["HAVE_NUMBA", "jit"]

try:  # pragma: no cover - exercised implicitly
    from numba import njit as _njit

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    HAVE_NUMBA = False
    _njit = None


def jit(func: Callable[..., Any] | None = None, **options: Any) -> Any:
    """Compile ``func`` with ``numba.njit(cache=True, **options)`` when numba is installed (``@jit`` or
    ``@jit(inline="always")``).

    Examples
    --------
    >>> @jit
    ... def twice(x):
    ...     return 2.0 * x
    >>> twice(1.5)
    3.0
    """
    if func is None:
        return lambda f: jit(f, **options)
    if _njit is None:  # pragma: no cover
        return func
    try:
        compiled = _njit(cache=True, **options)(func)
    except RuntimeError:  # no file to cache next to (interactive or doctest code)
        return _njit(**options)(func)
    _stamp_with_package(compiled, func)
    return compiled


def _stamp_with_package(compiled: Any, func: Callable[..., Any]) -> None:
    """Make ``compiled``'s disk cache stale whenever a module of ``func``'s package changes (numba's own
    stamp covers ``func``'s file only). numba's cache internals: without them, its own stamp stays."""
    try:
        cache_file = compiled._cache._cache_file
        cache_file._source_stamp = (cache_file._source_stamp, _package_stamp(Path(func.__code__.co_filename).parent))
    except (AttributeError, OSError):  # pragma: no cover - another numba, or sources that cannot be listed
        pass


_STAMPS: dict[Path, tuple[tuple[str, float, int], ...]] = {}


def _package_stamp(folder: Path) -> tuple[tuple[str, float, int], ...]:
    if folder not in _STAMPS:
        stats = []
        for entry in sorted(os.scandir(folder), key=lambda e: e.name):
            if entry.name.endswith(".py"):
                st = entry.stat()
                stats.append((entry.name, st.st_mtime, st.st_size))
        _STAMPS[folder] = tuple(stats)
    return _STAMPS[folder]
