"""Classical stability margins, delay included."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import PositiveFloat, model_validator

from synth.requirements.base import NEPER_PER_DB, Bound, Requirement, RequirementResult, fmt, register

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = ["MarginsRequirement"]


@register
class MarginsRequirement(Requirement):
    """Gain margin (dB), phase margin (deg) and optionally delay margin (s), each a lower bound.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    >>> r = MarginsRequirement(type="margins", gain_margin_db=6, phase_margin_deg=45).evaluate(
    ...     Loop(G, Controller("P", {"kp": 3.0})))
    >>> r.met, round(r.details["gain_margin_db"], 2), round(r.details["phase_margin_deg"], 1)
    (False, 1.79, 19.8)
    """

    type: Literal["margins"] = "margins"
    gain_margin_db: PositiveFloat | None = None
    phase_margin_deg: PositiveFloat | None = None
    delay_margin: PositiveFloat | None = None
    title: ClassVar[str] = "stability margins"
    bounds: ClassVar[dict[str, Bound]] = {"gain_margin_db": Bound("lower", "dB"),
                                          "phase_margin_deg": Bound("lower", "deg"),
                                          "delay_margin": Bound("lower", "s")}
    example: ClassVar[dict[str, Any]] = {"type": "margins", "gain_margin_db": 6.0, "phase_margin_deg": 45.0}

    @model_validator(mode="after")
    def _something(self) -> MarginsRequirement:
        if self.gain_margin_db is None and self.phase_margin_deg is None and self.delay_margin is None:
            raise ValueError("give at least one of gain_margin_db, phase_margin_deg, delay_margin")
        if self.phase_margin_deg is not None and self.phase_margin_deg >= 180:
            raise ValueError(f"phase_margin_deg must be below 180, got {self.phase_margin_deg:g}")
        return self

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        m = loop.margins()
        parts = []
        if self.gain_margin_db is not None:
            slack = (m.gain_margin_db - self.gain_margin_db) * NEPER_PER_DB
            parts.append((slack, "gain margin", m.gain_margin_db, self.gain_margin_db, "dB", m.phase_crossover))
        if self.phase_margin_deg is not None:
            slack = np.radians(m.phase_margin_deg - self.phase_margin_deg)
            parts.append((slack, "phase margin", m.phase_margin_deg, self.phase_margin_deg, "deg",
                          m.gain_crossover))
        if self.delay_margin is not None:
            slack = np.log(m.delay_margin / self.delay_margin) if m.delay_margin > 0 else -np.inf
            parts.append((slack, "delay margin", m.delay_margin, self.delay_margin, "s", m.gain_crossover))
        slack, name, value, bound, unit, w = min(parts, key=lambda p: p[0])
        texts = [f"{p[1]} {fmt(p[2])} {p[4]} (min {fmt(p[3])})" for p in parts]
        msg = f"{'; '.join(texts)}: {'met' if slack >= 0 else 'NOT met'}, tightest: {name}"
        return self.result(value=value, bound=bound, unit=unit, slack=slack, margin=value - bound,
                           binding_frequency=w, message=msg, binding=name, **m.to_dict())

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack: gain crossovers of all loops by batched polynomial roots, phase crossovers
        (the gain margin) by bisection on a shared grid (:meth:`~synth.loop_batch.LoopBatch.upper_gain_margins`)."""
        parts = []
        if self.gain_margin_db is not None:
            k_hi = batch.upper_gain_margins()
            with np.errstate(divide="ignore"):
                gm = np.where(np.isfinite(k_hi), 20 * np.log10(k_hi), np.inf)
            parts.append((gm - self.gain_margin_db) * NEPER_PER_DB)
        if self.phase_margin_deg is not None or self.delay_margin is not None:
            pm, dm = batch.phase_and_delay_margins()
            if self.phase_margin_deg is not None:
                parts.append(np.radians(pm - self.phase_margin_deg))
            if self.delay_margin is not None:
                with np.errstate(divide="ignore"):
                    parts.append(np.where(dm > 0, np.log(np.where(dm > 0, dm, 1.0) / self.delay_margin), -np.inf))
        return np.min(parts, axis=0)
