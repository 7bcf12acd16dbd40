"""Checks a command makes at the start of ``run``, before any computation, on the paths it will write.

A report folder holding a file of the same name that synth did not write, a ``--json`` file synth did
not write, or a place where nothing can be written is refused at once (one line, exit 2), so a refusal
costs no computation and leaves nothing behind. The writers check again when they write.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path


def check_outputs(folder: str | Path | None, names: Iterable[str] = (), files: Iterable[str | Path | None] = (),
                  force: bool = False, inputs: Iterable[str | Path | None] = ()) -> None:
    """Refuse now what would be refused after the computation.

    ``folder`` is a report folder (``None``: none written) and ``names`` the main files written there;
    ``files`` are single output files (``None`` and ``"-"``, standard output, are skipped). An output named twice
    (a ``--json`` that is the ``--out`` file, or a file of the report folder) or that is one of the command's
    ``inputs`` is refused too: one would overwrite the other.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "report.html").write_text("mine")
    >>> check_outputs(d, ["result.json", "report.html"])
    Traceback (most recent call last):
    synth.errors.OutputExistsError: ...report.html: exists and was not written by synth; not overwriting it ...
    >>> check_outputs(d / "new", ["report.html"], files=["-", None, d / "out.json"])
    >>> sorted(p.name for p in d.iterdir())  # nothing written
    ['report.html']
    >>> check_outputs(None, files=[d / "a.json"], inputs=[d / "a.json"])
    Traceback (most recent call last):
    synth.errors.SpecError: ...a.json: is an input of this command; writing the output there would overwrite it
    """
    from synth.errors import OutputExistsError, SpecError
    from synth.outputs import OutputDir, check_writable

    singles = [Path(f) for f in files if f is not None and str(f) != "-"]
    outputs = ([Path(folder) / n for n in names] if folder is not None else []) + singles
    seen: set[Path] = set()
    for path in outputs:
        if path.resolve() in seen:
            raise SpecError("is named as two outputs of this command; give each its own file", where=str(path))
        seen.add(path.resolve())
    for given in inputs:
        if given is not None and str(given) != "-" and Path(given).resolve() in seen:
            raise SpecError("is an input of this command; writing the output there would overwrite it",
                            where=str(given))
    if folder is not None:
        OutputDir(folder, force, expect=list(names))
    for file in files:
        if file is None or str(file) == "-":
            continue
        path = Path(file)
        check_writable(path, force)
        try:
            OutputDir(path.parent)  # the folder it goes in can be created and written
        except OutputExistsError as exc:  # named by the file the user gave, and the folder the message is about
            message = exc.message
            if message == "exists and is not a directory":
                message = f"its folder {path.parent} exists and is not a directory"
            raise OutputExistsError(message, where=str(path)) from None


def spec_name(path: str) -> str | None:
    """The ``name:`` of a spec file, read without building the spec (``None`` if it has none readable).

    Examples
    --------
    >>> spec_name("specs/x4_rotor.yaml"), spec_name("no/such/file.yaml")
    ('x4_rotor', None)
    """
    import yaml

    try:
        with open(path, encoding="utf-8") as handle:
            data = yaml.safe_load(handle)
    except (OSError, ValueError, yaml.YAMLError):
        return None
    name = data.get("name") if isinstance(data, dict) else None
    return name if isinstance(name, str) and name and "/" not in name and name not in (".", "..") else None
