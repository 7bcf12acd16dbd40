"""Writing output files without overwriting anything the user wrote.

A report folder keeps a manifest (``.synth-manifest.json``) of the files
synth wrote there, each with its SHA-256; those may be regenerated freely,
unless changed since (a user's edit is not overwritten without ``force``). Any other existing file
with the same name is left alone unless ``force`` is given. A single output
file (``--json FILE``) may be replaced only if synth wrote it (its JSON has
``"generator": "synth ..."``).
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import weakref
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from synth.errors import OutputExistsError
from synth.version import __version__

__all__ = ["GENERATOR", "MANIFEST", "OutputDir", "atomic_write_text", "check_writable", "dump_json", "to_jsonable",
           "write_json", "written_by_synth"]

MANIFEST = ".synth-manifest.json"
GENERATOR = f"synth {__version__}"


def written_by_synth(path: str | Path) -> bool:
    """Whether ``path`` is one of synth's own outputs, judged by its content.

    JSON carries ``"generator": "synth ..."``; HTML a ``<meta name="generator" content="synth ...">``;
    PNG a ``Software: synth`` text chunk; CSV a first line naming synth. Anything else is not synth's.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "a.json").write_text(dump_json({"x": 1})); _ = (d / "b.json").write_text('{"x": 1}')
    >>> written_by_synth(d / "a.json"), written_by_synth(d / "b.json"), written_by_synth(d / "missing.png")
    (True, False, False)
    """
    path = Path(path)
    try:
        head = path.read_bytes()[:4096]
    except OSError:
        return False
    suffix = path.suffix.lower()
    if suffix == ".json":
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError, UnicodeDecodeError):
            return False
        return isinstance(data, dict) and str(data.get("generator", "")).startswith("synth")
    if suffix in (".html", ".htm"):
        return b'<meta name="generator" content="synth' in head
    if suffix == ".png":
        return head.startswith(b"\x89PNG") and b"Software\x00synth" in head
    if suffix == ".csv":
        return head.lstrip(b"# ").startswith(b"synth")
    return False


def check_writable(path: Path, force: bool = False) -> None:
    """Raise :class:`OutputExistsError` if ``path`` exists and synth did not write it.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "notes.json"
    >>> _ = p.write_text("my notes")
    >>> check_writable(p)
    Traceback (most recent call last):
    ...
    synth.errors.OutputExistsError: ...notes.json: exists and was not written by synth; not overwriting ...
    """
    path = Path(path)
    if path.is_dir():
        raise OutputExistsError("is a directory", where=str(path))
    if path.exists() and not force and not written_by_synth(path):
        raise OutputExistsError(
            "exists and was not written by synth; not overwriting it (use --force to replace it)",
            where=str(path),
        )


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays and non-finite floats (``"inf"``, ``"-inf"``, ``null``) for JSON.

    Examples
    --------
    >>> import numpy as np
    >>> to_jsonable({"a": np.float64(2.0), "b": float("inf"), "c": [np.nan]})
    {'a': 2.0, 'b': 'inf', 'c': [None]}
    """
    import numpy as np

    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        if np.isnan(x):
            return None
        if np.isinf(x):
            return "inf" if x > 0 else "-inf"
        return x
    if isinstance(obj, complex):
        return [obj.real, obj.imag]
    return obj


def dump_json(data: dict[str, Any]) -> str:
    """JSON text with ``generator`` first, non-finite numbers made explicit."""
    return json.dumps({"generator": GENERATOR, **to_jsonable(data)}, indent=2) + "\n"


def write_json(path: str | Path, data: dict[str, Any], force: bool = False) -> Path:
    """Write ``data`` as JSON to ``path`` (refusing to replace a file synth did not write)."""
    path = Path(path)
    check_writable(path, force)
    return atomic_write_text(path, dump_json(data))


class OutputDir:
    """A report folder written all at once: files are staged, then moved into place by :meth:`commit`.

    Writers :meth:`claim` a name and write to the path returned, which lies in a hidden staging folder
    next to the report folder. :meth:`commit` first checks every claimed name (a file synth did not
    write is never replaced unless ``force``), then moves each staged file into place and records the
    names in the folder's manifest (``.synth-manifest.json``). A refused commit, an exception or an
    interrupted run leaves nothing behind: the staging folder is removed. synth recognizes its own
    earlier outputs by the manifest or by their content (:func:`written_by_synth`).

    Parameters
    ----------
    path : str or Path
        The report folder.
    force : bool
        Replace files synth did not write.
    expect : iterable of str
        Names the caller will write; checked at once (before any computation), so a refusal costs none.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> out = OutputDir(root / "report")
    >>> p = out.claim("result.json"); _ = p.write_text("{}")
    >>> (root / "report" / "result.json").exists()  # staged, not yet in place
    False
    >>> out.commit(); out.final(p) == root / "report" / "result.json", out.final(p).read_text()
    (True, '{}')
    >>> _ = (root / "report" / "notes.txt").write_text("mine")
    >>> OutputDir(root / "report", expect=["notes.txt"])
    Traceback (most recent call last):
    synth.errors.OutputExistsError: ...notes.txt: exists and was not written by synth; not overwriting it ...
    >>> sorted(q.name for q in root.iterdir())  # no staging folder left behind
    ['report']
    """

    def __init__(self, path: str | Path, force: bool = False, expect: Iterable[str] = ()) -> None:
        self.path = Path(path)
        self.force = force
        if self.path.exists() and not self.path.is_dir():
            raise OutputExistsError("exists and is not a directory", where=str(self.path))
        self.known, self.hashes = _manifest_files(self.path)
        self.written: list[str] = []
        for name in expect:
            self._check(name)
        _check_creatable(self.path)
        self._staging: Path | None = None
        self._earlier_staging: list[Path] = []
        self._cleanup: weakref.finalize | None = None

    def _check(self, name: str) -> None:
        target = self.path / name
        if not target.exists() or self.force:
            return
        recorded = self.hashes.get(name)
        if recorded is not None and recorded != _sha256(target):
            raise OutputExistsError(
                "was written by synth and changed since; not overwriting it (use --force or another --out)",
                where=str(target),
            )
        if name not in self.known and not written_by_synth(target):
            raise OutputExistsError(
                "exists and was not written by synth; not overwriting it (use --force or another --out)",
                where=str(target),
            )

    @property
    def staging(self) -> Path:
        """The hidden folder next to :attr:`path` where files are written before :meth:`commit`."""
        if self._staging is None:
            parent = self.path.parent
            parent.mkdir(parents=True, exist_ok=True)
            self._staging = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.", suffix=".synth-staging", dir=parent))
            self._cleanup = weakref.finalize(self, shutil.rmtree, self._staging, ignore_errors=True)
        return self._staging

    def claim(self, name: str) -> Path:
        """Staged path for ``name``; refuses at once a file in the folder that synth did not write."""
        self._check(name)
        if name not in self.written:
            self.written.append(name)
        target = self.staging / name
        target.parent.mkdir(parents=True, exist_ok=True)
        return target

    def final(self, staged: str | Path) -> Path:
        """Where a claimed (staged) path ends up after :meth:`commit`."""
        staged = Path(staged)
        for root in (self._staging, *self._earlier_staging):
            if root is not None and staged.is_relative_to(root):
                return self.path / staged.relative_to(root)
        return staged

    def discard(self) -> None:
        """Remove everything staged (nothing is moved into place)."""
        if self._cleanup is not None:
            self._cleanup()
        if self._staging is not None:
            self._earlier_staging.append(self._staging)
        self._staging, self._cleanup, self.written = None, None, []

    def commit(self) -> None:
        """Check every claimed name, move the staged files into place, update the manifest.

        Nothing is moved if any name is refused; the staging folder is removed either way.
        """
        try:
            for name in self.written:
                self._check(name)
            self.path.mkdir(parents=True, exist_ok=True)
            for name in self.written:
                staged = self.staging / name
                if staged.exists():
                    (self.path / name).parent.mkdir(parents=True, exist_ok=True)
                    os.replace(staged, self.path / name)
            files = sorted({f for f in {*self.written, *self.known} if (self.path / f).exists()})
            hashes = {f: _sha256(self.path / f) if f in self.written else self.hashes.get(f) for f in files}
            hashes = {f: h for f, h in hashes.items() if h is not None}
            atomic_write_text(self.path / MANIFEST, json.dumps({"generator": GENERATOR, "files": files,
                                                                "sha256": hashes}, indent=2) + "\n")
            self.known, self.hashes = set(files), hashes
        finally:
            self.discard()


def _manifest_files(folder: Path) -> tuple[set[str], dict[str, str]]:
    """The names a folder's manifest lists and the SHA-256 of each as synth wrote it (none in older manifests)."""
    manifest = folder / MANIFEST
    if not manifest.exists():
        return set(), {}
    try:
        data = json.loads(manifest.read_text(encoding="utf-8"))
        hashes = data.get("sha256", {})
        return set(data.get("files", [])), (dict(hashes) if isinstance(hashes, dict) else {})
    except (OSError, ValueError, AttributeError, TypeError):
        return set(), {}


def _sha256(path: Path) -> str:
    import hashlib

    return hashlib.sha256(path.read_bytes()).hexdigest()


def _check_creatable(path: Path) -> None:
    """Refuse at once a folder that cannot be created or written (before any computation): the folder itself if
    it exists, and the nearest existing folder above it (where the staging folder goes), each tried by making
    and removing an empty folder in it (permission bits say nothing for root, nor on /proc or a read-only
    mount)."""
    probe = path.parent if path.parent != path else path
    while not probe.exists():
        probe = probe.parent
    for folder in ([path] if path.is_dir() else []) + [probe]:
        if not folder.is_dir() or not os.access(folder, os.W_OK | os.X_OK) or not _can_make_folder_in(folder):
            raise OutputExistsError(f"cannot write here ({folder} is not a writable folder)", where=str(path))


def _can_make_folder_in(folder: Path) -> bool:
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".synth-probe.", dir=folder))
    except OSError:
        return False
    return True


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` through a temporary file in the same folder and an atomic rename.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = atomic_write_text(pathlib.Path(tempfile.mkdtemp()) / "a.txt", "one")
    >>> p.read_text(), [q.name for q in p.parent.iterdir()]
    ('one', ['a.txt'])
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as handle:
            handle.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
