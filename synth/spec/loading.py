"""Reading a spec: YAML text, a path, a text stream or a mapping, validated into a :class:`Spec`.

Loading is strict: an unknown key, a missing field, a string where a number belongs, a reversed
band, an unparsable transfer function or an unknown type each raise a
:class:`~synth.errors.SpecError` whose text is ``<file>:<line>: <key path>: <what is wrong>``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import yaml
from pydantic import ValidationError

from synth.errors import ModelError, SpecError
from synth.spec.document import Spec
from synth.spec.messages import key_path, line_of, spec_error
from synth.spec.plant_block import DATA_FOLDER

__all__ = ["load_spec", "parse_spec"]


class _Loader(yaml.SafeLoader):
    """SafeLoader that also reads ``1e4`` (no dot) as a float, as people write it."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
        |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
        |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
        |[-+]?\.(?:inf|Inf|INF)
        |\.(?:nan|NaN|NAN))$""",
        re.X,
    ),
    list("-+0123456789."),
)


def parse_spec(text: str, source: str = "<spec>") -> Spec:
    """Validate spec text (YAML).

    Examples
    --------
    >>> parse_spec("name: x\\nplant: {tf: '1/(s+1)'}\\ncontroller: {type: P}\\nrequirements: []")
    Traceback (most recent call last):
    ...
    synth.errors.SpecError: <spec>:4: requirements: the requirement list is empty; give at least one requirement
    """
    try:
        root = yaml.compose(text, Loader=_Loader)
        data = yaml.load(text, Loader=_Loader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{source}:{mark.line + 1}" if mark is not None else source
        problem = getattr(exc, "problem", None) or str(exc)
        raise SpecError(f"invalid YAML: {problem}", where=where) from None
    if data is None:
        raise SpecError("the spec file is empty", where=source)
    if not isinstance(data, dict):
        raise SpecError("the spec must be a mapping of keys (name, plant, controller, ...)", where=source)
    folder = Path(source).parent if source != "<spec>" else None
    try:
        spec = Spec.model_validate_json(json.dumps(data, default=str), strict=True, context={DATA_FOLDER: folder})
    except ValidationError as exc:
        raise spec_error(exc, source, root, data) from None
    if spec.plant.identify is not None:
        _check_identify_data(spec, source, root)
    return spec


def _check_identify_data(spec: Spec, source: str, root: yaml.Node | None) -> None:
    """Resolve ``plant.identify.data`` against the spec file's folder; a missing file is a spec error."""
    from synth.ident.from_spec import resolve_data

    try:
        path = resolve_data(spec.plant.identify.data, spec.plant.data_folder)
    except ModelError as exc:
        path, problem = None, exc.message
    else:
        problem = None if path.is_file() else f"data file {str(path)!r} not found"
    if problem:
        loc = ("plant", "identify", "data")
        line = line_of(root, loc)
        raise SpecError(problem, where=f"{source}:{line}: {key_path(loc)}" if line else f"{source}: {key_path(loc)}")


def load_spec(path: str | Path) -> Spec:
    """Read and validate a spec file.

    Parameters
    ----------
    path : str or Path
        A YAML spec file (see ``docs/spec-format.md``).

    Returns
    -------
    Spec

    Raises
    ------
    SpecError
        One line naming the file, line, key and problem.

    Examples
    --------
    >>> import tempfile, os
    >>> f = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)
    >>> _ = f.write("name: demo\\nplant: {tf: '1/(s+1)'}\\ncontroller: {type: P}\\n"
    ...             "requirements: [{type: bandwidth, min: 2}]\\n"); f.close()
    >>> load_spec(f.name).controller.type
    'P'
    >>> os.unlink(f.name)
    """
    path = Path(path)
    if not path.exists():
        raise SpecError("spec file not found", where=str(path))
    if path.is_dir():
        raise SpecError("is a directory, not a spec file", where=str(path))
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(f"cannot read spec file: {exc}", where=str(path)) from None
    return parse_spec(text, source=str(path))
