"""Swept spec values: a dotted path into the spec's data and the values it takes (``synth tradeoff --sweep``).

A requirement is picked by its ``label``, its ``type`` when unique, or its index; list items by index.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.errors import SpecError

__all__ = ["Sweep", "check_distinct", "item_index", "set_value"]


@dataclass
class Sweep:
    """One swept spec value.

    Examples
    --------
    >>> Sweep.parse("requirements.bandwidth.min=40:100:4").values
    [40.0, 60.0, 80.0, 100.0]
    >>> Sweep.parse("plant.delay=0,0.01").path
    'plant.delay'
    """

    path: str
    values: list[float]

    @classmethod
    def parse(cls, text: str) -> Sweep:
        """Parse ``PATH=start:stop:count`` or ``PATH=v1,v2,...``."""
        if "=" not in text:
            raise SpecError(f"sweep {text!r} needs the form PATH=start:stop:count or PATH=v1,v2,...",
                            where="--sweep")
        path, spec = (t.strip() for t in text.split("=", 1))
        try:
            if ":" in spec:
                start, stop, count = spec.split(":")
                n = int(count)
                if n < 1:
                    raise ValueError
                values = list(np.linspace(float(start), float(stop), n))
            else:
                items = spec.split(",")
                if len(items) > 1 and not all(v.strip() for v in items):
                    raise SpecError(f"sweep {text!r} has an empty item in its list of values", where="--sweep")
                values = [float(v) for v in items if v.strip()]
        except ValueError:
            raise SpecError(f"sweep {text!r}: values must be start:stop:count (count >= 1) or a list of numbers",
                            where="--sweep") from None
        if not values:
            raise SpecError(f"sweep {text!r} has no values", where="--sweep")
        return cls(path, [float(v) for v in values])

    @property
    def key(self) -> str:
        """Last path element (e.g. ``min``)."""
        return self.path.split(".")[-1] if not self.path.split(".")[-1].isdigit() else self.path.split(".")[-2]


def set_value(data: dict[str, Any], path: str, value: float) -> dict[str, Any]:
    """Copy of the spec data with ``path`` set to ``value``.

    Examples
    --------
    >>> d = {"requirements": [{"type": "bandwidth", "min": 60}]}
    >>> set_value(d, "requirements.bandwidth.min", 80.0)["requirements"][0]["min"]
    80.0
    """
    out = copy.deepcopy(data)
    parts = path.split(".")
    node: Any = out
    for i, part in enumerate(parts[:-1]):
        if isinstance(node, list):
            node = node[item_index(node, part, ".".join(parts[: i + 1]), parts[i - 1] if i else "")]
        elif isinstance(node, dict):
            if part not in node:
                raise SpecError(f"no key {part!r} in the spec", where=f"--sweep {path}")
            node = node[part]
        else:
            raise SpecError(f"{'.'.join(parts[:i])} is a value, not a section", where=f"--sweep {path}")
    last = parts[-1]
    if isinstance(node, list):
        node[item_index(node, last, path, parts[-2] if len(parts) > 1 else "")] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise SpecError(f"cannot set {path}", where=f"--sweep {path}")
    return out


def item_index(items: list, key: str, where: str, parent: str) -> int:
    """Position of the list item ``key`` names: an index, a ``label``, or a ``type`` held by one item only.

    Examples
    --------
    >>> reqs = [{"type": "margins", "label": "pm"}, {"type": "bandwidth"}]
    >>> item_index(reqs, "pm", "requirements.pm", "requirements"), item_index(reqs, "bandwidth", "", "")
    (0, 1)
    """
    if key.isdigit():
        if int(key) >= len(items):
            raise SpecError(f"index {key} out of range ({len(items)} items)", where=f"--sweep {where}")
        return int(key)
    labelled = [i for i, it in enumerate(items) if isinstance(it, dict) and it.get("label") == key]
    typed = [i for i, it in enumerate(items) if isinstance(it, dict) and it.get("type") == key]
    match = labelled or typed
    if len(match) == 1:
        return match[0]
    if not match:
        raise SpecError(f"no {parent or 'item'} with label or type {key!r}", where=f"--sweep {where}")
    what = "labelled" if labelled else "of type"
    raise SpecError(f"{len(match)} {parent or 'items'} {what} {key!r}: give a label or an index", where=f"--sweep {where}")


def check_distinct(data: dict[str, Any], sweeps: list[Sweep]) -> None:
    """Refuse two sweeps that name one value (a label and a type, say): each would overwrite the other.

    Examples
    --------
    >>> d = {"requirements": [{"type": "margins", "label": "pm", "phase_margin_deg": 45}]}
    >>> check_distinct(d, [Sweep.parse("requirements.pm.phase_margin_deg=20,30"),
    ...                    Sweep.parse("requirements.margins.phase_margin_deg=40,50")])
    Traceback (most recent call last):
    synth.errors.SpecError: --sweep: the two sweeps 'requirements.pm.phase_margin_deg' and \
'requirements.margins.phase_margin_deg' name the same value; sweep it once
    """
    if len(sweeps) != 2:
        return
    both = set_value(set_value(data, sweeps[0].path, -1.5e300), sweeps[1].path, 1.5e300)
    if set_value(both, sweeps[1].path, -2.5e300) == set_value(both, sweeps[0].path, -2.5e300):
        raise SpecError(f"the two sweeps {sweeps[0].path!r} and {sweeps[1].path!r} name the same value; "
                        "sweep it once", where="--sweep")
