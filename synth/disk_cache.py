"""Results kept on disk between runs, keyed by everything that determines them.

A result is stored under the SHA-256 of the caller's key (the inputs' bytes and settings) and a fingerprint
of the code and libraries that compute it (every ``synth`` source file, numpy, scipy, casadi): any change to one
of them is a miss, never a stale result. A file that cannot be read back is a miss too. Entries live in
:func:`cache_dir` ``/<kind>`` (the :data:`KEEP` newest of each kind are kept);
``SYNTH_RESULT_CACHE=off`` turns every kind off. Users: the identification of a spec's record
(:mod:`synth.ident.result_cache`) and the design report's studies that depend on the spec alone
(:mod:`synth.report.studies`).
"""

from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
from collections.abc import Callable, Iterable
from functools import cache
from pathlib import Path
from typing import TypeVar

__all__ = ["KEEP", "cache_dir", "cached", "code_fingerprint", "enabled"]

T = TypeVar("T")

KEEP = 8
"""Entries kept per kind; older ones are removed when a new one is written."""

_OFF = ("off", "0", "no", "false")


def cache_dir() -> Path:
    """Folder for generated data and kept results: ``$SYNTH_CACHE``, else ``~/.cache/synth``, else the system temp folder.

    Examples
    --------
    >>> cache_dir().name in ("synth", "synth-cache") or "SYNTH_CACHE" in os.environ
    True
    """
    if os.environ.get("SYNTH_CACHE"):
        return Path(os.environ["SYNTH_CACHE"])
    home = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "synth"
    try:
        home.mkdir(parents=True, exist_ok=True)
        probe = home / ".write-test"
        probe.write_text("")
        probe.unlink()
        return home
    except OSError:
        return Path(tempfile.gettempdir()) / "synth-cache"


def enabled(variable: str = "SYNTH_RESULT_CACHE") -> bool:
    """Whether the on-disk cache is on: neither ``SYNTH_RESULT_CACHE`` nor ``variable`` is ``off``/``0``/``no``.

    Examples
    --------
    >>> isinstance(enabled(), bool)
    True
    """
    return all(os.environ.get(name, "on").strip().lower() not in _OFF for name in {"SYNTH_RESULT_CACHE", variable})


@cache
def code_fingerprint() -> str:
    """SHA-256 over every ``synth`` source file and the versions of numpy, scipy and casadi.

    Examples
    --------
    >>> len(code_fingerprint())
    64
    """
    from importlib.metadata import version  # the installed versions, without importing casadi (0.1 s)

    digest = hashlib.sha256(" ".join(version(name) for name in ("numpy", "scipy", "casadi")).encode())
    root = Path(__file__).resolve().parent
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def cached(kind: str, key: Iterable[bytes | str], compute: Callable[[], T]) -> T:
    """``compute()``, or its earlier result for the same ``key`` parts and code (stored under ``kind``).

    The caller names in ``key`` everything the result depends on; the code is added here. Writing is atomic
    (a temporary file renamed into place); a cache that cannot be written only costs time.

    Examples
    --------
    >>> calls = []
    >>> def work():
    ...     calls.append(1)
    ...     return {"k": 2.0}
    >>> cached("example", ["k/(s+p)"], work) == cached("example", ["k/(s+p)"], work), len(calls) <= 1
    (True, True)
    """
    digest = hashlib.sha256()
    for part in key:
        data = part.encode() if isinstance(part, str) else part
        digest.update(len(data).to_bytes(8, "little"))
        digest.update(data)
    digest.update(code_fingerprint().encode())
    folder = cache_dir() / kind
    entry = folder / f"{digest.hexdigest()}.pickle"
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
        pass
    return result
