"""Plain-text tables and requirement rows for terminal output."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from synth.requirements.base import Requirement, RequirementResult, fmt


def table(headers: list[str], rows: Iterable[list[str]]) -> str:
    """Left-aligned text table.

    Examples
    --------
    >>> print(table(["a", "bb"], [["1", "2"]]))
    a  bb
    -  --
    1  2
    """
    rows = [list(map(str, r)) for r in rows]
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)]
    lines = ["  ".join(h.ljust(w) for h, w in zip(headers, widths)).rstrip(),
             "  ".join("-" * w for w in widths)]
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    return "\n".join(lines)


def requirement_rows(results: list[RequirementResult], requirements: list[Requirement]) -> list[list[str]]:
    """Rows ``requirement, value, bound, slack, binding frequency, met`` for a table.

    ``results`` are the check's rows (stability first, then one per requirement in spec order);
    each row's bound reads as its requirement's class writes it.

    Examples
    --------
    >>> from synth.spec import load_spec; from synth.check import check
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> [row[2] for row in requirement_rows(check(spec, "P(3)").requirements, list(spec.requirements))]
    ['stable', '<= -15 dB', '>= 60 rad/s', '<= 10000 PWM/s']
    """
    rows = []
    reqs = iter(requirements)
    for r in results:
        if r.type == "stability":
            value = "stable" if r.met else "not certified" if "not certified stable" in r.message else \
                "marginally stable" if r.message.startswith("closed loop marginally stable") else \
                f"{int(r.value)} unstable root(s)"  # the line below the table says the same
            bound = "stable"
        else:
            value, bound = f"{fmt(r.value)} {r.unit}", next(reqs).report_row(r).bound_text()
        plant = f" [{r.plant}]" if r.plant and r.plant != "nominal" else ""
        rows.append([r.label + plant, value, bound, f"{r.slack:+.4g}",
                     fmt(r.binding_frequency), "met" if r.met else "NOT MET"])
    return rows


REQUIREMENT_HEADERS = ["requirement", "value", "bound", "slack [Np]", "binding w [rad/s]", ""]


def print_requirements(results: list[RequirementResult], requirements: list[Requirement], out: Any) -> None:
    """Print the requirement table and each requirement's plain-language line."""
    print(table(REQUIREMENT_HEADERS, requirement_rows(results, requirements)), file=out)
    print(file=out)
    for r in results:
        print(f"- {r.message}", file=out)


def name_values(rows: list[tuple[str, str]], notes: Iterable[str] = ()) -> str:
    """Two aligned columns (name, value with unit), then one ``note:`` line per note.

    Examples
    --------
    >>> print(name_values([("w180", "3.262 rad/s"), ("phase delay", "0.0761 s")], ["exact"]))
      w180         3.262 rad/s
      phase delay  0.0761 s
    note: exact
    """
    width = max((len(name) for name, _ in rows), default=0)
    lines = [f"  {name:<{width}}  {value}" for name, value in rows] + [f"note: {n}" for n in notes]
    return "\n".join(lines)
