"""Identification results kept on disk between runs, keyed by what determines them.

Re-running ``synth design`` on a spec whose ``plant: {identify: ...}`` block and
record have not changed (the usual loop: edit a requirement, run again) reuses the
identification instead of fitting the record again. The key is the SHA-256 of the
record file's bytes, the identify settings and units, and a fingerprint of the code
and libraries that compute the fit (:func:`synth.disk_cache.code_fingerprint`): any
change to one of them is a miss, never a stale result. Entries live in
:func:`synth.disk_cache.cache_dir` ``/identify`` (the 8 newest are kept);
``SYNTH_IDENTIFY_CACHE=off`` (or ``SYNTH_RESULT_CACHE=off``) turns the cache off.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from synth.disk_cache import cached
from synth.disk_cache import enabled as _enabled

__all__ = ["cached_result", "enabled"]


def enabled() -> bool:
    """Whether the identification cache is on (``SYNTH_IDENTIFY_CACHE`` and ``SYNTH_RESULT_CACHE`` are not
    ``off``/``0``/``no``).

    Examples
    --------
    >>> isinstance(enabled(), bool)
    True
    """
    return _enabled("SYNTH_IDENTIFY_CACHE")


def cached_result(path: Path, settings: tuple[Any, ...], compute: Callable[[], Any]) -> Any:
    """``compute()``, or its earlier result for the same record bytes, ``settings`` and code.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "r.csv"; _ = p.write_text("t,u,y\\n0,0,0\\n")
    >>> calls = []
    >>> def work():
    ...     calls.append(1)
    ...     return {"k": 2.0}
    >>> cached_result(p, ("k/(s+p)",), work) == cached_result(p, ("k/(s+p)",), work), len(calls) <= 1
    (True, True)
    """
    if not enabled():
        return compute()
    return cached("identify", [Path(path).read_bytes(), repr(settings)], compute)
