"""Check a controller against every requirement of a spec, on every plant it lists."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements.base import Requirement, RequirementResult, fmt
from synth.spec import Spec

__all__ = ["CheckResult", "QuickCheck", "check", "evaluate_all", "margin_slack", "quick_check", "stability_result"]


@dataclass
class CheckResult:
    """Outcome of :func:`check`.

    Attributes
    ----------
    spec : str
        Spec name.
    controller : Controller
        The controller checked.
    feasible : bool
        Closed loop stable on every plant and every requirement met.
    requirements : list of RequirementResult
        Closed-loop stability first, then each requirement in spec order; for
        several plants, the worst plant's result (its label in ``plant``).
    per_plant : dict
        Every requirement on every plant, keyed by plant label.
    """

    spec: str
    controller: Controller
    feasible: bool
    requirements: list[RequirementResult]
    per_plant: dict[str, list[RequirementResult]] = field(default_factory=dict)

    def failed(self) -> list[RequirementResult]:
        """Requirements that are not met."""
        return [r for r in self.requirements if not r.met]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict with ``feasible``, ``controller`` and ``requirements``."""
        return {
            "spec": self.spec,
            "feasible": self.feasible,
            "controller": self.controller.to_dict(),
            "requirements": [r.to_dict() for r in self.requirements],
            "per_plant": {k: [r.to_dict() for r in v] for k, v in self.per_plant.items()}
            if len(self.per_plant) > 1 else {},
        }


def stability_result(loop: Loop) -> RequirementResult:
    """Closed-loop stability as a requirement result.

    The slack is the two-sided loop-gain margin in nepers (``ln`` of the
    smallest gain factor, up or down, that makes the loop marginal) when the
    loop is stable, and minus the number of unstable closed-loop roots when
    it is not.

    Examples
    --------
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    >>> r = stability_result(Loop(G, Controller("P", {"kp": 3.0})))
    >>> r.met, round(r.slack, 4)
    (True, 0.2064)
    """
    st = loop.stability()
    if st.stable:
        k_lo, k_hi, w_lo, w_hi = loop.gain_factors
        up = np.log(k_hi) if np.isfinite(k_hi) else np.inf
        down = -np.log(k_lo) if k_lo > 0 else np.inf
        slack = min(up, down)
        w = w_hi if up <= down else w_lo
        msg = st.describe()
        if np.isfinite(slack):
            msg += f"; a loop-gain change by a factor {fmt(np.exp(slack))} makes it marginal"
        else:
            msg += "; no loop-gain change within 80 dB makes it marginal"
    else:
        slack, w = -float(max(st.unstable_poles, 1)), st.marginal_frequency
        msg = st.describe()
    return RequirementResult(
        type="stability", label="closed-loop stability", value=float(st.unstable_poles), bound=0.0,
        unit="unstable roots", slack=float(slack), margin=-float(st.unstable_poles),
        binding_frequency=None if w is None else float(w), met=bool(st.stable), message=msg,
        details=st.to_dict(),
    )


def evaluate_all(requirements: list[Requirement], plants: list[Plant], controller: Controller,
                 per_decade: int = 80) -> tuple[list[RequirementResult], dict[str, list[RequirementResult]]]:
    """Evaluate stability and every requirement on every plant; also return the worst per requirement."""
    per_plant: dict[str, list[RequirementResult]] = {}
    for i, plant in enumerate(plants):
        label = plant.label or f"plant {i + 1}"
        loop = Loop(plant, controller)
        results = [stability_result(loop)] + [r.evaluate(loop, per_decade) for r in requirements]
        for r in results:
            r.plant = label
        per_plant[label] = results
    worst = [
        min((per_plant[label][k] for label in per_plant), key=lambda r: r.slack)
        for k in range(len(requirements) + 1)
    ]
    return worst, per_plant


def check(spec: Spec, controller: Controller | str, per_decade: int = 80) -> CheckResult:
    """Check ``controller`` against every requirement of ``spec``.

    Parameters
    ----------
    spec : Spec
        Loaded spec (see :func:`synth.load_spec`).
    controller : Controller or str
        The controller, or its text such as ``"P(3)"``; any type may be checked,
        whatever structure the spec designs.
    per_decade : int
        Frequency-grid density for band and peak searches (peaks are refined
        by local optimization, so the result hardly depends on it).

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> result = check(load_spec("specs/x4_rotor.yaml"), "P(3)")
    >>> result.feasible, [round(r.slack, 3) for r in result.requirements]
    (True, [inf, 0.129, 0.326, 1.897])
    """
    if isinstance(controller, str):
        controller = Controller.from_string(controller)
    worst, per_plant = evaluate_all(list(spec.requirements), spec.plants(), controller, per_decade)
    feasible = all(r.met for r in worst)
    return CheckResult(spec.name, controller, feasible, worst, per_plant)


@dataclass
class QuickCheck:
    """Outcome of :func:`quick_check`.

    Attributes
    ----------
    feasible : bool
        What :func:`check` would say.
    min_slack : float
        The smallest slack of :func:`check`'s results (stability's two-sided gain margin included) when
        feasible; ``-inf`` when not (the check stopped at the first failure).
    """

    feasible: bool
    min_slack: float


def quick_check(spec: Spec, controller: Controller, per_decade: int = 80, margins: bool = True) -> QuickCheck:
    """:func:`check`'s verdict and smallest slack, with the work a failure makes unnecessary left out.

    Searches on the exact check (:mod:`synth.synthesis.pattern`, :mod:`synth.synthesis.exact_search`) make
    most of their checks outside the feasible set. This one counts each plant's unstable roots first, then
    evaluates the requirements, the ones that simulate (:attr:`~synth.requirements.base.Requirement.costly`)
    last, and stops at the first that fails (a costly one is first asked whether a cheaper evaluation proves it
    fails: :meth:`~synth.requirements.base.Requirement.fails_surely`); the gain margins of a stable loop
    (stability's slack) are computed only when everything passed. The verdict and slack are :func:`check`'s;
    with ``margins=False`` the slack leaves the gain margins out (:func:`margin_slack` gives them: a search that
    reads the slack only to break ties between equal scores computes them only then).

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> q = quick_check(spec, Controller("P", {"kp": 3.0}))
    >>> q.feasible, round(q.min_slack, 3), min(r.slack for r in check(spec, "P(3)").requirements) == q.min_slack
    (True, 0.129, True)
    >>> quick_check(spec, Controller("P", {"kp": 0.5}))
    QuickCheck(feasible=False, min_slack=-inf)
    """
    loops = [Loop(plant, controller) for plant in spec.plants()]
    if not all(loop.stability().stable for loop in loops):
        return QuickCheck(False, -np.inf)
    slacks = []
    for requirement in sorted(spec.requirements, key=lambda r: r.costly):  # stable sort: spec order otherwise
        for loop in loops:
            if requirement.costly and requirement.fails_surely([loop])[0]:  # a cheaper proof that it fails
                return QuickCheck(False, -np.inf)
            slack = requirement.slack(loop, per_decade)
            if not slack >= 0:  # a NaN fails too, as in check
                return QuickCheck(False, -np.inf)
            slacks.append(slack)
    if margins:
        slacks += [stability_result(loop).slack for loop in loops]
    return QuickCheck(True, float(min(slacks, default=np.inf)))


def margin_slack(spec: Spec, controller: Controller) -> float:
    """The smallest of stability's slacks over the spec's plants (:func:`stability_result`: the two-sided loop-gain
    margin in nepers of a stable loop), the part of :func:`quick_check`'s slack that ``margins=False`` leaves out.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> c = Controller("P", {"kp": 3.0})
    >>> min(quick_check(spec, c, margins=False).min_slack, margin_slack(spec, c)) == quick_check(spec, c).min_slack
    True
    """
    return float(min(stability_result(Loop(plant, controller)).slack for plant in spec.plants()))
