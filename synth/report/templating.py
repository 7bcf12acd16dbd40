"""Rendering the report templates to byte-stable HTML, and numbers rounded for byte-stable JSON.

The same inputs give byte-identical files: blank lines left by template tags whose condition is false are
dropped (so adding a section or an include to a template does not change the reports that do not show it),
and floats are written with 12 significant digits (so the last bits of a floating-point sum, which may differ
between BLAS builds and thread counts, do not reach the files).
"""

from __future__ import annotations

import re
from typing import Any

from jinja2 import Environment, FileSystemBytecodeCache, PackageLoader

from synth.disk_cache import cache_dir, enabled

__all__ = ["JSON_DIGITS", "WALL_CLOCK_KEYS", "render", "reproducible", "unit_text"]

JSON_DIGITS = 12
"""Significant digits of every float in a report's JSON."""

WALL_CLOCK_KEYS = frozenset({"solve_time", "seconds"})
"""Keys holding wall-clock seconds, left out of report files (they differ from run to run)."""



def _bytecode_cache() -> FileSystemBytecodeCache | None:
    """The templates' compiled code kept between runs (jinja2 recompiles a template whose source changed), in
    :func:`synth.disk_cache.cache_dir` ``/templates``: compiling the design report's templates took 0.1 s of
    every run. None (compiled each run) when ``SYNTH_RESULT_CACHE=off`` or the folder cannot be made."""
    if not enabled():
        return None
    folder = cache_dir() / "templates"
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return FileSystemBytecodeCache(str(folder))


_ENV = Environment(loader=PackageLoader("synth.report", "templates"), autoescape=True,
                   bytecode_cache=_bytecode_cache())
_BLANK_LINES = re.compile(r"\n(?:[ \t]*\n)+")


def render(template: str, **context: Any) -> str:
    """Render ``synth/report/templates/<template>`` with ``context``; whitespace-only lines dropped.

    Examples
    --------
    >>> html = render("tradeoff.html.j2", r={"generator": "synth", "spec": "x", "points": [], "sweeps": [],
    ...               "objective": {"description": "d"}}, command="c", figure="f.png", rows=[], columns=[], f=str)
    >>> "\\n\\n" in html, html.startswith("<!DOCTYPE html>")
    (False, True)
    """
    return _BLANK_LINES.sub("\n", _ENV.get_template(template).render(**context))


def reproducible(data: Any, digits: int = JSON_DIGITS) -> Any:
    """``data`` with every float rounded to ``digits`` significant digits and the wall-clock keys
    (:data:`WALL_CLOCK_KEYS`) left out (containers copied).

    Examples
    --------
    >>> reproducible({"a": [2.5685629177241616, 1e-300, 3], "b": "x", "c": float("inf"), "solve_time": 0.31})
    {'a': [2.56856291772, 1e-300, 3], 'b': 'x', 'c': inf}
    """
    if isinstance(data, float):
        return float(f"{data:.{digits}g}")
    if isinstance(data, dict):
        return {k: reproducible(v, digits) for k, v in data.items() if k not in WALL_CLOCK_KEYS}
    if isinstance(data, (list, tuple)):
        return [reproducible(v, digits) for v in data]
    return data


def unit_text(unit: str | None, brackets: bool = False) -> str:
    """A unit to follow a number: ``""`` for none (never ``[]`` or a lone ``/``), else ``" rad/s"`` or
    ``" [rad/s]"``.

    Examples
    --------
    >>> unit_text("rad/s"), unit_text(""), unit_text("PWM", brackets=True), unit_text(None, brackets=True)
    (' rad/s', '', ' [PWM]', '')
    """
    if not unit:
        return ""
    return f" [{unit}]" if brackets else f" {unit}"
