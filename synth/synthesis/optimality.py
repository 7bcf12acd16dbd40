"""What a certified design's optimality rests on: which stage produced it and whether that stage converged.

The certificate proves a design feasible; it says nothing about how good it is. A design from an IPOPT
round that converged is a local optimum of the NLP on the design grid; where IPOPT stopped at its iteration
limit, or the convex-concave iteration stopped before its tolerance, the design is feasible but not shown to
be a local optimum. The verdict and ``result.json`` (``optimality``) say which.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

__all__ = ["Optimality", "optimality_of"]

_METHODS = {"convex": "the convex-concave iteration", "nlp": "the NLP polish (IPOPT)",
            "nlp from screen": "the NLP polish (IPOPT) from a screened start",
            "nlp from pattern search": "the NLP polish (IPOPT) from the pattern search's design",
            "nlp from initial": "the NLP polish (IPOPT) from the spec's initial controller"}


@dataclass(frozen=True)
class Optimality:
    """The evidence for a design's optimality.

    Attributes
    ----------
    local : bool
        The stage that produced the design converged (a KKT point of its problem on the design grid).
    stage : str
        That stage (``"convex"``, ``"nlp"``, ``"nlp from screen"``, ``"screen"``, ``"pattern search"``,
        ``"initial"``, ``"nlp from initial"`` or ``"ascent probe"``).
    basis : str
        One sentence, for the verdict.
    """

    local: bool
    stage: str
    basis: str

    def to_dict(self) -> dict[str, object]:
        """JSON-ready dict.

        Examples
        --------
        >>> Optimality(True, "nlp", "a local optimum").to_dict()["local"]
        True
        """
        return asdict(self)


def optimality_of(stage: str, controller: str, unconverged: set[str], screened: str = "",
                  keeping: float | None = None) -> Optimality:
    """The optimality evidence of the design ``controller`` (its text) chosen from ``stage``.

    Parameters
    ----------
    stage : str
        The stage the certificate chose the design from.
    controller : str
        ``str(controller)`` of the chosen design.
    unconverged : set of str
        The designs (as text) that a stage returned without converging: where IPOPT stopped at its iteration
        limit or the polish's rounds ran out while its answer still asked for another round, or a
        convex-concave run that ended before its tolerance.
    screened : str
        What the pattern search and the random screen of the bounds found beyond the local stages (clauses), if
        they ran.
    keeping : float, optional
        The ``|1 + L|`` every iterate keeps on the grid (:class:`~synth.synthesis.convex_settings.ConvexSettings`'
        ``stability_level``): the local optimum is one of the problem with that constraint added.

    Examples
    --------
    >>> optimality_of("nlp", "PI(kp=1, ki=2)", set(), keeping=0.05).basis
    'a local optimum on the design grid, keeping |1 + L| >= 0.05 on it (the NLP polish (IPOPT) converged)'
    >>> o = optimality_of("nlp", "PI(kp=1, ki=2)", {"PI(kp=1, ki=2)"})
    >>> o.local, o.basis[:76]
    (False, 'not shown to be a local optimum (the NLP polish (IPOPT) stopped at its itera')
    >>> o.basis[76:160]
    'tion limit, or its rounds ran out while the answer still moved); the design is certi'

    """
    method = _METHODS.get(stage, stage)
    if stage == "pattern search":
        return Optimality(False, stage, "not shown to be a local optimum (a pattern search on the exact check "
                          "improved the best design of the stages before, none of which was shown to be a local "
                          "optimum); the design is "
                          "certified feasible, a better one may exist" + (f"; {screened}" if screened else ""))
    if stage == "ascent probe":
        return Optimality(False, stage, "not shown to be a local optimum (a converged stage's design failed the "
                          "first-order test on the exact requirements: steps along directions that raise the objective "
                          "and every nearly active limit improved it); the design is certified feasible, a better one "
                          "may exist" + (f"; {screened}" if screened else ""))
    if stage == "initial":
        return Optimality(False, stage, "not optimized: the spec's initial controller, certified; no stage found a "
                          "better design" + (f"; {screened}" if screened else ""))
    if stage == "screen":
        return Optimality(False, stage, "not optimized: a point of the random screen of the bounds, certified"
                          + (f"; {screened}" if screened else ""))
    if controller in unconverged:
        why = f"{method} stopped at its iteration limit, or its rounds ran out while the answer still moved" \
            if stage.startswith("nlp") else \
            f"{method} ended without a KKT point (a bisection on the objective, or its iteration limit)"
        return Optimality(False, stage, f"not shown to be a local optimum ({why}); the design is "
                          "certified feasible, a better one may exist" + (f"; {screened}" if screened else ""))
    kept = f", keeping |1 + L| >= {keeping:g} on it" if keeping else ""
    return Optimality(True, stage, f"a local optimum on the design grid{kept} ({method} converged)"
                      + (f"; {screened}" if screened else ""))
