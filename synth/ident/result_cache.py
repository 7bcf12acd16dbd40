"""Identification results kept on disk between runs, keyed by what determines them.

Re-running ``synth design`` on a spec whose ``plant: {identify: ...}`` block and
record have not changed (the usual loop: edit a requirement, run again) reuses the
identification instead of fitting the record again. The key is the SHA-256 of the
record file's bytes, the identify settings and units, and a fingerprint of the code
and libraries that compute the fit (every ``synth`` source file, numpy, scipy,
casadi): any change to one of them is a miss, never a stale result. A file that
cannot be read back is a miss too. Entries live in :func:`synth.ident.x4_record.cache_dir`
``/identify`` (the 8 newest are kept); ``SYNTH_IDENTIFY_CACHE=off`` turns the cache off.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any

__all__ = ["KEEP", "cached_result", "code_fingerprint", "enabled"]

KEEP = 8
"""Entries kept; older ones are removed when a new one is written."""


def enabled() -> bool:
    """Whether the on-disk cache is on (``SYNTH_IDENTIFY_CACHE`` is not ``off``/``0``/``no``).

    Examples
    --------
    >>> isinstance(enabled(), bool)
    True
    """
    return os.environ.get("SYNTH_IDENTIFY_CACHE", "on").strip().lower() not in ("off", "0", "no", "false")


@cache
def code_fingerprint() -> str:
    """SHA-256 over every ``synth`` source file and the versions of numpy, scipy and casadi.

    Examples
    --------
    >>> len(code_fingerprint())
    64
    """
    import casadi
    import numpy
    import scipy

    digest = hashlib.sha256(f"{numpy.__version__} {scipy.__version__} {casadi.__version__}".encode())
    root = Path(__file__).resolve().parents[1]
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def cached_result(path: Path, settings: tuple[Any, ...], compute: Callable[[], Any]) -> Any:
    """``compute()``, or its earlier result for the same record bytes, ``settings`` and code.

    Examples
    --------
    >>> import pathlib
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
    from synth.ident.x4_record import cache_dir

    key = hashlib.sha256()
    key.update(Path(path).read_bytes())
    key.update(repr(settings).encode())
    key.update(code_fingerprint().encode())
    folder = cache_dir() / "identify"
    entry = folder / f"{key.hexdigest()}.pickle"
    try:
        with entry.open("rb") as handle:
            return pickle.load(handle)
    except Exception:  # missing, truncated or written by another version: a miss
        pass
    result = compute()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        with os.fdopen(fd, "wb") as handle:
            pickle.dump(result, handle, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, entry)
        for old in sorted(folder.glob("*.pickle"), key=lambda p: p.stat().st_mtime)[:-KEEP]:
            old.unlink(missing_ok=True)
    except OSError:
        pass  # a cache that cannot be written only costs time
    return result
