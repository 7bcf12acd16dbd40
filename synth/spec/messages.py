"""One-line spec errors: the first pydantic error as ``<file>:<line>: <key path>: <what is wrong>``.

The line comes from the YAML node tree; the key path drops pydantic's internal tags; an unknown
key gets a "did you mean" hint from the keys the block accepts.
"""

from __future__ import annotations

import difflib
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from synth.errors import SpecError
from synth.requirements import REQUIREMENT_TYPES
from synth.requirements.base import tagged_type
from synth.sim.spec import BLOCK_TAGS, DISTURBANCE_TAGS, SIMULATION_TAGS
from synth.spec.document import Spec

__all__ = ["key_path", "line_of", "spec_error"]


def line_of(root: yaml.Node | None, loc: tuple[Any, ...]) -> int | None:
    """Line (1-based) of the deepest key of ``loc`` found in the YAML node tree ``root``.

    Parameters
    ----------
    root : yaml.Node or None
        ``yaml.compose(text)`` of the spec (None for a spec given as a mapping: no lines).
    loc : tuple
        Key path, e.g. ``("requirements", 1, "min")``.

    Returns
    -------
    int or None

    Examples
    --------
    >>> root = yaml.compose("name: x\\nrequirements:\\n  - {type: bandwidth}\\n  - {type: bandwidth, min: 2}\\n")
    >>> line_of(root, ("requirements", 1, "min"))
    4
    >>> line_of(None, ("name",)) is None
    True
    """
    node = root
    line = node.start_mark.line + 1 if node is not None else None
    for key in loc:
        if isinstance(node, yaml.MappingNode):
            nxt = None
            for k, v in node.value:
                if isinstance(k, yaml.ScalarNode) and k.value == str(key):
                    nxt, line = v, k.start_mark.line + 1
                    break
            if nxt is None:
                break
            node = nxt
        elif isinstance(node, yaml.SequenceNode) and isinstance(key, int) and key < len(node.value):
            node = node.value[key]
            line = node.start_mark.line + 1
        else:
            break
    return line


def _clean_loc(loc: tuple[Any, ...]) -> tuple[Any, ...]:
    out: list[Any] = []
    for i, part in enumerate(loc):
        parent = loc[i - 2] if i > 1 else None
        if (
            isinstance(part, str)
            and i > 0
            and isinstance(loc[i - 1], int)
            and ((parent == "requirements" and part in REQUIREMENT_TYPES)
                 or (parent in ("actuator", "sensor", "disturbances") and part in SIMULATION_TAGS))
        ):
            continue  # discriminated-union tag inserted by pydantic (not a key of that name: a variant's 'delay')
        if isinstance(part, str) and ("[" in part or part.startswith("function-")):
            continue
        out.append(part)
    return tuple(out)


def key_path(loc: tuple[Any, ...]) -> str:
    """The key path as a spec author writes it.

    Examples
    --------
    >>> key_path(("requirements", 1, "min"))
    'requirements[1].min'
    >>> key_path(())
    '(top level)'
    """
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(top level)"


def _allowed_keys(loc: tuple[Any, ...], data: Any) -> list[str]:
    """Keys the model at ``loc[:-1]`` accepts (for 'did you mean' hints)."""
    model: Any = Spec
    node = data
    for part in loc[:-1]:
        if isinstance(part, int):
            node = node[part] if isinstance(node, list) and part < len(node) else None
            if model == "requirements":
                model = tagged_type(REQUIREMENT_TYPES, node)
            elif isinstance(model, dict):  # a list of tagged models (simulation blocks, disturbances)
                model = tagged_type(model, node)
            continue
        node = node.get(part) if isinstance(node, dict) else None
        if model is Spec and part == "requirements":
            model = "requirements"
            continue
        field = getattr(model, "model_fields", {}).get(part)
        if field is None:
            return []
        tagged = _tagged_members(field.annotation)
        if tagged:
            model = tagged
            continue
        candidates = [field.annotation, *getattr(field.annotation, "__args__", ())]
        model = next((c for c in candidates if isinstance(c, type) and issubclass(c, BaseModel)), None)
    fields = getattr(model, "model_fields", None)
    return list(fields) if isinstance(fields, dict) else []


def _tagged_members(annotation: Any) -> dict[str, type[BaseModel]]:
    """``{tag: model}`` when ``annotation`` is a list of models told apart by a ``type`` literal."""
    from typing import get_args, get_origin

    if get_origin(annotation) is not list:
        return {}
    found: dict[str, type[BaseModel]] = {}
    stack = list(get_args(annotation))
    while stack:
        item = stack.pop()
        if isinstance(item, type) and issubclass(item, BaseModel):
            field = item.model_fields.get("type")
            tags = get_args(field.annotation) if field is not None else ()
            if tags and all(isinstance(t, str) for t in tags):
                found.update({t: item for t in tags})
        else:
            stack.extend(get_args(item))
    return found


def _message(err: dict[str, Any], data: Any, loc: tuple[Any, ...]) -> str:
    kind = err["type"]
    given = err.get("input")
    if kind == "missing":
        return "missing (required)"
    if kind == "extra_forbidden":
        allowed = [k for k in _allowed_keys(loc, data) if k != "type"]
        near = difflib.get_close_matches(str(loc[-1]), allowed, n=1)
        hint = f"; did you mean {near[0]!r}?" if near else (f"; allowed: {', '.join(allowed)}" if allowed else "")
        return f"unknown key {loc[-1]!r}{hint}"
    if kind in {"union_tag_invalid", "union_tag_not_found"} and loc and (loc[0] == "simulation" or "actuator" in loc):
        # a no_limit_cycle requirement's actuator holds blocks too
        what = "disturbance" if "disturbances" in loc else "block"
        expected = ", ".join(DISTURBANCE_TAGS if what == "disturbance" else BLOCK_TAGS)
        if kind == "union_tag_not_found":
            return f"{what} has no 'type'; expected one of: {expected}"
        return f"unknown {what} type {err['ctx']['tag']!r}; expected one of: {expected}"
    if kind == "union_tag_invalid":
        return (f"unknown requirement type {err['ctx']['tag']!r}; expected one of: "
                f"{', '.join(REQUIREMENT_TYPES)}")
    if kind == "union_tag_not_found":
        return f"requirement has no 'type'; expected one of: {', '.join(REQUIREMENT_TYPES)}"
    if kind == "finite_number":
        return f"expected a finite number, got {given!r}"
    if kind in {"float_type", "float_parsing", "int_type"}:
        return f"expected a number, got {given!r}"
    if kind in {"string_type"}:
        return f"expected text, got {given!r}"
    if kind in {"tuple_type", "list_type", "dict_type", "model_type"}:
        what = {"tuple_type": "a list [low, high]", "list_type": "a list", "dict_type": "a mapping",
                "model_type": "a mapping of keys"}[kind]
        return f"expected {what}, got {given!r}"
    if kind in {"too_short", "too_long"}:
        if loc and loc[-1] == "requirements":
            return "the requirement list is empty; give at least one requirement"
        if str(err.get("ctx", {}).get("field_type", "")).lower() == "list":  # a list of items, not a pair
            return f"needs at least {err['ctx'].get('min_length', 1)} item(s), got {given!r}"
        return f"expected exactly 2 numbers [low, high], got {given!r}"
    if kind in {"greater_than", "greater_than_equal"}:
        limit = err["ctx"].get("gt", err["ctx"].get("ge"))
        return f"must be {'>' if kind == 'greater_than' else '>='} {limit}, got {given!r}"
    msg = str(err.get("msg", "invalid value"))
    return msg.removeprefix("Value error, ")


def spec_error(exc: ValidationError, source: str, root: yaml.Node | None, data: Any) -> SpecError:
    """Turn the first pydantic error into a one-line :class:`SpecError`.

    Parameters
    ----------
    exc : pydantic.ValidationError
        From validating ``data`` as a :class:`~synth.spec.document.Spec`.
    source : str
        The file name (or ``"<spec>"``) the message starts with.
    root : yaml.Node or None
        The YAML node tree, for the line number (None: no line).
    data : object
        The validated data, for "did you mean" hints.

    Examples
    --------
    >>> data = {"name": "x", "plant": {"tf": "1/(s+1)", "dlay": 0}, "controller": {"type": "P"},
    ...         "requirements": [{"type": "bandwidth", "min": 2}]}
    >>> try:
    ...     Spec.model_validate(data)
    ... except ValidationError as exc:
    ...     print(spec_error(exc, "<spec>", None, data))
    <spec>: plant.dlay: unknown key 'dlay'; did you mean 'delay'?
    """
    errors = exc.errors(include_url=False)
    # a misspelled key shows up as "unknown key" plus "missing": the first says more
    errors.sort(key=lambda e: e["type"] != "extra_forbidden")
    err = errors[0]
    loc = _clean_loc(tuple(err["loc"]))
    if err["type"] in {"union_tag_invalid", "union_tag_not_found"}:
        loc = (*loc, "type")
    message = _message(err, data, loc)
    line = line_of(root, loc)
    if err["type"] == "value_error":  # a check across a block's keys names the key first: point at its line
        key = message.split(" ", 1)[0]
        line = line_of(root, (*loc, key)) or line
    where = f"{source}:{line}" if line else source
    return SpecError(message, where=f"{where}: {key_path(loc)}")
