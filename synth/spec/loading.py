"""Reading a spec: YAML text, a path, a text stream or a mapping, validated into a :class:`Spec`.

Loading is strict: an unknown key, a missing field, a string where a number belongs, a reversed
band, an unparsable transfer function or an unknown type each raise a
:class:`~synth.errors.SpecError` whose text is ``<file>:<line>: <key path>: <what is wrong>``.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import ValidationError

from synth.errors import ModelError, SpecError
from synth.spec.document import Spec
from synth.spec.messages import key_path, line_of, spec_error
from synth.spec.plant_block import DATA_FOLDER

__all__ = ["NO_SOURCE", "SPEC_SUFFIXES", "load_spec", "parse_spec", "parse_text"]


class _Loader(yaml.SafeLoader):
    """SafeLoader that also reads ``1e4`` (no dot) as a float, as people write it, and refuses a key given twice in
    one mapping (plain YAML keeps the last silently: a second ``plant:`` would replace the first unseen)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        first: dict[str, int] = {}
        for key_node, _ in node.value:
            if isinstance(key_node, yaml.ScalarNode) and key_node.tag != "tag:yaml.org,2002:merge":
                if key_node.value in first:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"key {key_node.value!r} given twice (first on line {first[key_node.value]})",
                        key_node.start_mark)
                first[key_node.value] = key_node.start_mark.line + 1
        return super().construct_mapping(node, deep)


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


SPEC_SUFFIXES = (".yaml", ".yml", ".json")
"""File name endings that make a one-line string a path rather than YAML text."""

NO_SOURCE = "<spec>"
"""Name of a spec given as text or a mapping, in messages (it has no file)."""


def parse_spec(spec: Any, source: str | None = None) -> Spec:
    """Validate a spec given as a mapping, YAML text, a path or a text stream.

    Parameters
    ----------
    spec : Mapping, str, os.PathLike or text stream
        - a mapping (``dict``) with the keys of a spec file (numpy numbers are fine);
        - YAML text;
        - a path (a ``Path``, or a one-line string ending in ``.yaml``, ``.yml`` or ``.json`` or naming a
          file that exists), read as :func:`load_spec` reads it;
        - a text stream (anything with ``read()``, e.g. an open file or ``io.StringIO``);
        - a :class:`~synth.spec.document.Spec`, returned as it is.
    source : str, optional
        Name that error messages start with, and whose folder ``plant.identify.data`` is relative to.
        Default: the file's name for a path or an open file, ``"<spec>"`` otherwise.

    Returns
    -------
    Spec

    Raises
    ------
    SpecError
        One line ``<source>[:<line>]: <key path>: <what is wrong>`` (no line for a mapping).

    Examples
    --------
    >>> data = {"name": "demo", "plant": {"tf": "23/(s+10)"}, "controller": {"type": "P"},
    ...         "requirements": [{"type": "bandwidth", "min": 20}]}
    >>> spec = parse_spec(data)
    >>> spec == parse_spec("name: demo\\nplant: {tf: '23/(s+10)'}\\ncontroller: {type: P}\\n"
    ...                    "requirements: [{type: bandwidth, min: 20}]")
    True
    >>> parse_spec("specs/x4_rotor.yaml").name
    'x4_rotor'
    >>> parse_spec({**data, "requirements": [{"type": "bandwidth", "min": "fast"}]})
    Traceback (most recent call last):
    ...
    synth.errors.SpecError: <spec>: requirements[0].min: expected a number, got 'fast'
    >>> parse_spec("name: x\\nplant: {tf: '1/(s+1)'}\\ncontroller: {type: P}\\nrequirements: []")
    Traceback (most recent call last):
    ...
    synth.errors.SpecError: <spec>:4: requirements: the requirement list is empty; give at least one requirement
    """
    if isinstance(spec, Spec):
        return spec
    if isinstance(spec, Mapping):
        return _parse_mapping(spec, source or NO_SOURCE)
    if isinstance(spec, os.PathLike) or (isinstance(spec, str) and _names_a_file(spec)):
        return load_spec(spec)
    if isinstance(spec, str):
        if spec.strip() and "\n" not in spec.strip() and not spec.strip().startswith("{") and ": " not in spec:
            raise SpecError(f"{spec!r} is neither a spec file nor a spec's YAML text (a mapping of keys)",
                            where=source or NO_SOURCE)
        return parse_text(spec, source or NO_SOURCE)
    if callable(getattr(spec, "read", None)):
        name = getattr(spec, "name", None)
        where = source or (name if isinstance(name, str) else NO_SOURCE)
        try:
            text = spec.read()
            if isinstance(text, bytes):
                text = text.decode("utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise SpecError(f"cannot read spec stream: {exc}", where=where) from None
        if not isinstance(text, str):
            raise SpecError(f"the stream gave {type(text).__name__}, not text", where=where)
        return parse_text(text, where)
    raise SpecError(f"cannot read a spec from a {type(spec).__name__}; give a mapping, YAML text, "
                    "a path or a text stream", where=source or NO_SOURCE)


def _names_a_file(text: str) -> bool:
    """A one-line string is a path if it ends like a spec file or names an existing file."""
    one_line = text.strip()
    if not one_line or "\n" in one_line or one_line.startswith("{"):
        return False
    return one_line.lower().endswith(SPEC_SUFFIXES) or Path(one_line).is_file()


def _json_value(value: Any) -> Any:
    """``json.dumps`` fallback: numpy numbers and arrays as Python ones, anything else as text (as YAML gives it)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


def _parse_mapping(data: Mapping[str, Any], source: str, root: yaml.Node | None = None) -> Spec:
    if data.get("simulation") is not None:  # requirements judged under the simulation: blocks get a copy of them
        from synth.requirements.simulated import bind_simulation

        data = {**data, "requirements": bind_simulation(data.get("requirements"), data["simulation"])}
    try:
        text = json.dumps(data, default=_json_value)
    except (TypeError, ValueError) as exc:
        raise SpecError(f"the spec mapping cannot be read: {exc}", where=source) from None
    folder = Path(source).parent if source != NO_SOURCE else None
    try:
        spec = Spec.model_validate_json(text, strict=True, context={DATA_FOLDER: folder})
    except ValidationError as exc:
        raise spec_error(exc, source, root, data) from None
    if spec.plant.identify is not None:
        _check_identify_data(spec, source, root)
    return spec


def parse_text(text: str, source: str = NO_SOURCE) -> Spec:
    """Validate spec text (YAML); ``source`` names it in messages.

    Examples
    --------
    >>> parse_text("name: x\\nplant: {tf: '1/(s+1)'}\\ncontroller: {type: P}\\n"
    ...            "requirements: [{type: bandwidth, min: two}]", "my.yaml")
    Traceback (most recent call last):
    ...
    synth.errors.SpecError: my.yaml:4: requirements[0].min: expected a number, got 'two'
    """
    loader = _Loader(text)  # composed once: the node tree for line numbers, constructed into the data
    try:
        root = loader.get_single_node()
        data = None if root is None else loader.construct_document(root)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{source}:{mark.line + 1}" if mark is not None else source
        problem = getattr(exc, "problem", None) or str(exc)
        raise SpecError(f"invalid YAML: {problem}", where=where) from None
    finally:
        loader.dispose()
    if data is None:
        raise SpecError("the spec file is empty", where=source)
    if not isinstance(data, dict):
        raise SpecError("the spec must be a mapping of keys (name, plant, controller, ...)", where=source)
    return _parse_mapping(data, source, root)


def _check_identify_data(spec: Spec, source: str, root: yaml.Node | None) -> None:
    """Resolve ``plant.identify.data`` against the spec file's folder; a missing file is a spec error."""
    from synth.ident.from_spec import resolve_data

    try:
        path = resolve_data(spec.plant.identify.data, spec.plant.data_folder)
    except ModelError as exc:
        path, problem = None, exc.message
    else:
        problem = (None if path.is_file() else f"data file {str(path)!r} is a folder, not a file" if path.is_dir()
                   else f"data file {str(path)!r} not found")
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
    return parse_text(text, source=str(path))
