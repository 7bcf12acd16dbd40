"""Registries of solver forms: one form per requirement type and solver, found by the type, never by an
``isinstance`` ladder.

:mod:`synth.synthesis.convex_forms` keeps :data:`~synth.synthesis.convex_forms.CONVEX_FORMS` (filled by
its ``@convex_form(Type, exact=...)`` entries) and :mod:`synth.synthesis.nlp_forms` keeps
:data:`~synth.synthesis.nlp_forms.NLP_FORMS` (``@nlp_form(Type, exact=...)``). A requirement type with no
entry is a :class:`~synth.errors.SpecError` naming it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from synth.errors import SpecError
from synth.requirements.base import Requirement

__all__ = ["FormEntry", "FormRegistry"]


@dataclass(frozen=True)
class FormEntry:
    """One registered form.

    Attributes
    ----------
    requirement : type
        The requirement class it encodes.
    build : callable
        The function that writes the form (its signature is the solver's).
    exact : bool
        The form is the requirement itself on the solver's frequencies (not an approximation or a
        partial encoding): the convex form an inner approximation that touches the exact constraint
        with the same gradient, the NLP form the same set.
    """

    requirement: type[Requirement]
    build: Callable[..., Any]
    exact: bool


class FormRegistry:
    """Forms of one solver, by requirement type.

    Examples
    --------
    >>> from synth.requirements import PeakSensitivity, SlewRate
    >>> forms = FormRegistry("demo")
    >>> @forms.register(PeakSensitivity, exact=True)
    ... def peak(req): return f"|S| <= {req.max_db}"
    >>> forms.entry(PeakSensitivity(max_db=6)).build(PeakSensitivity(max_db=6)), PeakSensitivity in forms
    ('|S| <= 6.0', True)
    >>> forms.entry(SlewRate(rate_limit=1, max_error=1, band=(0, 1)))
    Traceback (most recent call last):
    ...
    synth.errors.SpecError: requirements: requirement type 'slew_rate' (SlewRate) has no demo form
    """

    def __init__(self, solver: str) -> None:
        self.solver = solver
        self.entries: dict[type[Requirement], FormEntry] = {}

    def register(self, requirement: type[Requirement], *, exact: bool) -> Callable[[Callable], Callable]:
        """Decorator: ``build`` is the form of ``requirement`` (decorators stack for shared forms)."""

        def decorate(build: Callable) -> Callable:
            self.entries[requirement] = FormEntry(requirement, build, exact)
            return build

        return decorate

    def remove(self, requirement: type[Requirement]) -> None:
        """Forget the form of ``requirement`` (tests that register a throwaway type)."""
        self.entries.pop(requirement, None)

    def __contains__(self, requirement: type[Requirement]) -> bool:
        return requirement in self.entries

    def entry(self, requirement: Requirement | type[Requirement]) -> FormEntry:
        """The form of a requirement (or requirement type); :class:`SpecError` naming the type when
        it has none."""
        cls = requirement if isinstance(requirement, type) else type(requirement)
        found = self.entries.get(cls)
        if found is None:
            name = cls.model_fields["type"].default if "type" in cls.model_fields else cls.__name__
            raise SpecError(f"requirement type {name!r} ({cls.__name__}) has no {self.solver} form",
                            where="requirements")
        return found
