"""Writing output files without overwriting anything the user wrote.

A report folder keeps a manifest (``.synth-manifest.json``) of the files
synth wrote there; those may be regenerated freely. Any other existing file
with the same name is left alone unless ``force`` is given. A single output
file (``--json FILE``) may be replaced only if synth wrote it (its JSON has
``"generator": "synth ..."``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from synth.errors import OutputExistsError
from synth.version import __version__

__all__ = ["GENERATOR", "MANIFEST", "OutputDir", "check_writable", "dump_json", "to_jsonable", "write_json"]

MANIFEST = ".synth-manifest.json"
GENERATOR = f"synth {__version__}"


def _written_by_synth(path: Path) -> bool:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, UnicodeDecodeError):
        return False
    return isinstance(data, dict) and str(data.get("generator", "")).startswith("synth")


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
    if path.exists() and not force and not _written_by_synth(path):
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
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(dump_json(data), encoding="utf-8")
    return path


class OutputDir:
    """A report folder whose synth-written files are tracked in a manifest.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = OutputDir(pathlib.Path(tempfile.mkdtemp()) / "report")
    >>> p = out.claim("result.json"); _ = p.write_text("{}"); out.commit()
    >>> OutputDir(out.path).claim("result.json").name  # ours: may be rewritten
    'result.json'
    """

    def __init__(self, path: str | Path, force: bool = False) -> None:
        self.path = Path(path)
        self.force = force
        if self.path.exists() and not self.path.is_dir():
            raise OutputExistsError("exists and is not a directory", where=str(self.path))
        self.known: set[str] = set()
        manifest = self.path / MANIFEST
        if manifest.exists():
            try:
                self.known = set(json.loads(manifest.read_text(encoding="utf-8")).get("files", []))
            except (OSError, ValueError):
                self.known = set()
        self.written: list[str] = []

    def claim(self, name: str) -> Path:
        """Path for ``name`` inside the folder; refuses a file synth did not write."""
        target = self.path / name
        if target.exists() and name not in self.known and not self.force:
            raise OutputExistsError(
                "exists and was not written by synth; not overwriting it (use --force or another --out)",
                where=str(target),
            )
        self.path.mkdir(parents=True, exist_ok=True)
        self.written.append(name)
        return target

    def commit(self) -> None:
        """Record the files written (plus earlier ones still present) in the manifest."""
        files = sorted(set(self.written) | {f for f in self.known if (self.path / f).exists()})
        (self.path / MANIFEST).write_text(json.dumps({"generator": GENERATOR, "files": files}, indent=2) + "\n",
                                          encoding="utf-8")
