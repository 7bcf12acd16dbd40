"""The NLP polishes from the random screen's starts (:mod:`synth.synthesis.screen`), and how the design's verdict
words the near misses among them."""

from __future__ import annotations

import numpy as np

from synth.controllers import Controller
from synth.spec import Spec
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.nlp import polish
from synth.synthesis.screen import SCREEN_ITERATIONS, screen_near_improving
from synth.synthesis.start_spread import near_starts_for

__all__ = ["near_misses_polished", "near_misses_text", "polished_from"]


def polished_from(spec: Spec, starts: list[Controller], terms: list[tuple[str, str, float]], grid: np.ndarray,
                  settings: ConvexSettings, unconverged: set[str]) -> list[tuple[str, Controller]]:
    """Screened starts and what a short NLP polish (3 rounds of :data:`SCREEN_ITERATIONS`) made of each, as
    candidates for the certificate; where a polish stopped unconverged joins ``unconverged`` (as text).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "requirements": [{"type": "bandwidth",
    ...                    "min": 1.0}], "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}}})
    >>> out = polished_from(spec, [Controller("PI", {"kp": 1.0, "ki": 1.0})], [], np.logspace(-2, 2, 81),
    ...                     ConvexSettings(), set())
    >>> out[0][0], all(kind == "nlp from screen" for kind, _ in out[1:])
    ('screen', True)
    """
    out: list[tuple[str, Controller]] = []
    for c in starts:
        res = polish(list(spec.requirements), spec.plants(), c, spec.controller.all_bounds(), terms, grid,
                     settings.per_decade, settings.stability_level, rounds=3, max_iter=SCREEN_ITERATIONS)
        unconverged.update(h["controller"] for h in res.history if h.get("offered"))
        out.extend([("screen", c), *(("nlp from screen", r) for r in reversed(res.candidates))])
    return out


def _near_starts_text(count: int) -> str:
    """The ``count`` near misses polished from (:func:`synth.synthesis.screen.screen_near_improving`), in words.

    Examples
    --------
    >>> _near_starts_text(1)
    'the one that misses them by the least'
    """
    return "the one that misses them by the least" + (
        " and the least violating one apart from it in the box" if count > 1 else "")


def _near_outcome_text(count: int, led: int | None) -> str:
    """What the polishes from ``count`` near misses gave: ``led`` is the one whose polish gave the design.

    Examples
    --------
    >>> _near_outcome_text(1, 0), _near_outcome_text(2, 1), _near_outcome_text(2, None)
    ('led to this design', '(the second led to this design)', '(both ended at no better design)')
    """
    if count == 1:
        return "ended at no better design" if led is None else "led to this design"
    return "(both ended at no better design)" if led is None else \
        f"(the {('first', 'second')[led]} led to this design)"


def near_misses_polished(spec: Spec, terms: list[tuple[str, str, float]], above: float, grid: np.ndarray,
                         settings: ConvexSettings, unconverged: set[str]
                         ) -> tuple[list[Controller], list[list[tuple[str, Controller]]]]:
    """The near misses that score above ``above`` (:func:`synth.synthesis.screen.screen_near_improving`, as many as
    :func:`synth.synthesis.start_spread.near_starts_for` asks) and what :func:`polished_from` made of each.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)^3"}, "requirements": [{"type":
    ...                    "peak_sensitivity", "max_db": 3}], "controller": {"type": "PI", "bounds": {"kp": [0, 5],
    ...                    "ki": [0, 5]}}, "objective": {"maximize": "integral_gain"}})
    >>> near, polished = near_misses_polished(spec, [("integral_gain", "maximize", 1.0)], 0.3, np.logspace(-2, 2, 81),
    ...                                       ConvexSettings(), set())
    >>> len(near), [kind for kind, _ in polished[0]][0]
    (1, 'screen')
    """
    near = screen_near_improving(spec, terms, above, keep=near_starts_for(spec))
    return near, [polished_from(spec, [c], terms, grid, settings, unconverged) for c in near]


def near_misses_text(polished: list[list[tuple[str, Controller]]], passed: tuple[str, Controller] | None) -> str:
    """The verdict's words for the polishes from the near misses (:func:`near_misses_polished`), given the design
    certified after them.

    Examples
    --------
    >>> c = Controller("P", {"kp": 1.0})
    >>> near_misses_text([[("screen", c)]], ("nlp", c))[-75:]
    'an NLP polish from the one that misses them by the least led to this design'
    """
    led = [k for k, p in enumerate(polished) if passed is not None and any(c is passed[1] for _, c in p)]
    return (", and of those that score better but miss the requirements, "
            + ("an NLP polish from " if len(polished) == 1 else "NLP polishes from ")
            + _near_starts_text(len(polished)) + " " + _near_outcome_text(len(polished), led[0] if led else None))
