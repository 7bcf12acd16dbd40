"""The results of a step verdict (:mod:`synth.sim.verdict`): what one run says, the evidence a verdict rests
on, and the verdict itself with its one-line summary and JSON form."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from synth.sim.horizon import HorizonPlan
from synth.sim.limitcycle import REPEAT
from synth.sim.metrics import NonlinearStepMetrics
from synth.sim.results import SimResult

__all__ = ["Evidence", "Judgement", "StepVerdict"]


@dataclass(frozen=True)
class Judgement:
    """What one run says (see :func:`synth.sim.verdict.judge`).

    Attributes
    ----------
    verdict : str or None
        ``settled``, ``limit_cycle`` or ``diverging``; None when this run does not decide.
    criterion : str
        The rule that decided, or the one that failed.
    cycles : int
        Whole cycles seen in the last half of the run.
    growing : bool
        The run grows (a second growing run confirms divergence).
    wait : float
        Seconds after which an actuator block that holds a still output while the command winds lets go at
        most (:class:`synth.sim.holding.Winding`); ``inf`` otherwise.
    """

    verdict: str | None
    criterion: str
    cycles: int
    growing: bool = False
    wait: float = float("inf")


@dataclass(frozen=True)
class Evidence:
    """Why a verdict is what it is.

    Attributes
    ----------
    horizon : float
        Simulated time of the run the verdict rests on (s).
    dt : float
        Sample time (s).
    samples : int
        Samples of that run.
    cycles : int
        Whole cycles seen in its last half.
    horizons : tuple of float
        Every horizon tried, in order (each one a fresh run from rest).
    cap : float
        Longest horizon allowed (s).
    criterion : str
        The rule that decided, or why nothing did.
    plan : HorizonPlan
        How the first horizon was chosen.
    """

    horizon: float
    dt: float
    samples: int
    cycles: int
    horizons: tuple[float, ...]
    cap: float
    criterion: str
    plan: HorizonPlan

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (``plan`` as a dict).

        Examples
        --------
        >>> plan = HorizonPlan(5.0, 0.5, True, 3.2, None, "linear loop settles")
        >>> Evidence(5.0, 0.001, 5001, 0, (5.0,), 160.0, "in the band", plan).to_dict()["samples"]
        5001
        """
        out = {k: getattr(self, k) for k in self.__dataclass_fields__}
        out["horizons"] = list(self.horizons)
        out["plan"] = self.plan.to_dict()
        return out


@dataclass(frozen=True)
class StepVerdict:
    """Result of :func:`synth.sim.verdict.step_verdict`.

    Attributes
    ----------
    verdict : str
        One of :data:`synth.sim.verdict.VERDICTS`.
    evidence : Evidence
    metrics : NonlinearStepMetrics
        Step metrics of the last run.
    result : SimResult
        The last run.
    """

    verdict: str
    evidence: Evidence
    metrics: NonlinearStepMetrics
    result: SimResult

    @property
    def determined(self) -> bool:
        """The runs decided (the verdict is not ``undetermined``)."""
        return self.verdict != "undetermined"

    def summary(self, unit: str = "") -> str:
        """One line: the verdict and its evidence.

        Examples
        --------
        >>> from synth.plant import Plant; from synth.controllers import Controller
        >>> from synth.sim.loops import NonlinearLoop; from synth.sim.verdict import step_verdict
        >>> v = step_verdict(NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1})), 0, 1)
        >>> v.summary()[:56], v.summary()[-38:]
        ('settled: within 0.01 % of the step over the last 2.4 s, ', '(horizon 9.55 s, 9551 samples of 1 ms)')
        """
        e = self.evidence
        unit = f" {unit}" if unit else ""
        where = f"horizon {e.horizon:.3g} s, {e.samples} samples of {e.dt * 1000:.3g} ms"
        lc = self.metrics.limit_cycle
        if self.verdict == "limit_cycle" and lc.periodic is False and lc.amplitude_range and lc.period_range:
            (a0, a1), (p0, p1) = lc.amplitude_range, lc.period_range
            return (f"limit cycle, oscillating but not periodic: amplitude {a0:.4g} to {a1:.4g}{unit}, cycles of "
                    f"{p0:.4g} to {p1:.4g} s (mean {lc.period:.4g} s); the cycles do not repeat within "
                    f"{100 * REPEAT:g} % ({e.cycles} cycles in the last half; {e.criterion}; {where})")
        if self.verdict == "limit_cycle":
            return (f"limit cycle: amplitude {lc.amplitude:.4g}{unit}, period {lc.period:.4g} s "
                    f"({e.cycles} cycles in the last half; {e.criterion}; {where})")
        if self.verdict == "undetermined":
            return f"undetermined within {e.horizon:.3g} s: {e.criterion} ({e.cycles} cycles seen; {where})"
        return f"{self.verdict.replace('_', ' ')}: {e.criterion} ({where})"

    def to_dict(self) -> dict[str, Any]:
        """``{"verdict", "evidence", **metrics}`` (JSON-ready; the time series is left out).

        Examples
        --------
        >>> from synth.plant import Plant; from synth.controllers import Controller
        >>> from synth.sim.loops import NonlinearLoop; from synth.sim.verdict import step_verdict
        >>> v = step_verdict(NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1})), 0, 1)
        >>> d = v.to_dict(); d["verdict"], d["evidence"]["samples"], round(d["final_value"], 3)
        ('settled', 9551, 0.5)
        """
        return {"verdict": self.verdict, "evidence": self.evidence.to_dict(), **self.metrics.to_dict()}
