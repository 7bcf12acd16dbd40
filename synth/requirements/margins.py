"""Classical stability margins, delay included."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import PositiveFloat, model_validator

from synth.requirements.base import NEPER_PER_DB, Bound, Requirement, RequirementResult, fmt, register

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = ["UNSTABLE_SLACK", "MarginsRequirement", "closed_loop_unstable", "unstable_result", "with_unstable_rows"]


@register
class MarginsRequirement(Requirement):
    """Gain margin (dB), phase margin (deg) and optionally delay margin (s), each a lower bound.

    The gain margin is two-sided: the loop must stay stable when its gain rises by ``gain_margin_db``
    and when it falls by as much (an open-loop unstable plant, or a conditionally stable loop, has a
    lower gain limit; both limits are in ``details``). Margins of a closed loop that is not stable are
    not margins: the requirement is then not met, with the reason, and its value is ``nan``.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    >>> r = MarginsRequirement(type="margins", gain_margin_db=6, phase_margin_deg=45).evaluate(
    ...     Loop(G, Controller("P", {"kp": 3.0})))
    >>> r.met, round(r.details["gain_margin_db"], 2), round(r.details["phase_margin_deg"], 1)
    (False, 1.79, 19.8)
    >>> unstable = Loop(Plant.from_string("10/((s-1)*(s+5))"), Controller("P", {"kp": 0.4}))
    >>> r = MarginsRequirement(phase_margin_deg=45).evaluate(unstable)
    >>> r.met, r.message
    (False, 'closed loop UNSTABLE (1 root(s) in the closed right half-plane): phase margin undefined, NOT met')
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
        if closed_loop_unstable(loop):
            given = [f.replace("_db", "").replace("_deg", "").replace("_", " ") for f in self.bounds
                     if getattr(self, f) is not None]
            return unstable_result(self, loop, " and ".join(given), **m.to_dict())
        parts = self._parts(m)
        slack, name, value, bound, unit, w = min(parts, key=lambda p: p[0])
        texts = [f"{p[1]} {fmt(p[2])} {p[4]} (min {fmt(p[3])})" for p in parts]
        if self.gain_margin_db is not None and -m.lower_gain_margin_db < m.gain_margin_db:  # the downward one binds
            texts[0] = (f"gain margin {fmt(parts[0][2])} dB downward (min {fmt(self.gain_margin_db)}; the loop gain "
                        f"may fall by that much, and rise by {fmt(m.gain_margin_db)} dB)")
        msg = f"{'; '.join(texts)}: {'met' if slack >= 0 else 'NOT met'}, tightest: {name}"
        return self.result(value=value, bound=bound, unit=unit, slack=slack, margin=value - bound,
                           binding_frequency=w, message=msg, binding=name, **m.to_dict())

    def _parts(self, m: Any) -> list[tuple[float, str, float, float, str, float | None]]:
        """``(slack, name, value, bound, unit, frequency)`` of each margin the requirement bounds, from the loop's
        margins ``m`` (the gain margin the nearer of the upward and the downward one)."""
        parts = []
        if self.gain_margin_db is not None:
            two_sided = min(m.gain_margin_db, -m.lower_gain_margin_db)
            w = m.phase_crossover if m.gain_margin_db <= -m.lower_gain_margin_db else m.lower_phase_crossover
            parts.append(((two_sided - self.gain_margin_db) * NEPER_PER_DB, "gain margin", two_sided,
                          self.gain_margin_db, "dB", w))
        if self.phase_margin_deg is not None:
            parts.append((np.radians(m.phase_margin_deg - self.phase_margin_deg), "phase margin", m.phase_margin_deg,
                          self.phase_margin_deg, "deg", m.gain_crossover))
        if self.delay_margin is not None:
            slack = np.log(m.delay_margin / self.delay_margin) if m.delay_margin > 0 else -np.inf
            parts.append((slack, "delay margin", m.delay_margin, self.delay_margin, "s", m.gain_crossover))
        return parts

    def part_slacks(self, loop: Loop, per_decade: int = 80) -> list[float]:
        """Each bounded margin's slack; an unstable closed loop's slack (:meth:`slack`) for each.

        Examples
        --------
        >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
        >>> loop = Loop(Plant.from_string("1/(s*(s+1))"), Controller("P", {"kp": 1.0}))
        >>> [round(s, 3) for s in MarginsRequirement(gain_margin_db=6, phase_margin_deg=45).part_slacks(loop)]
        [inf, 0.119]
        """
        if closed_loop_unstable(loop):
            return [self.slack(loop, per_decade)] * len(self._parts(loop.margins()))
        return [float(p[0]) for p in self._parts(loop.margins())]

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack, the scalar form's numbers: gain crossovers of all loops by batched polynomial
        roots, the two-sided gain margin from the factors of
        :meth:`~synth.loop_batch.LoopBatch.gain_margin_factors`; loops that are not closed-loop stable carry
        the scalar verdict (:func:`with_unstable_rows`)."""
        parts = []
        if self.gain_margin_db is not None:
            k_lo, k_hi = batch.gain_margin_factors()
            with np.errstate(divide="ignore"):
                gm = np.where(np.isfinite(k_hi), 20 * np.log10(k_hi), np.inf)
                lower = np.where(k_lo > 0, -20 * np.log10(np.where(k_lo > 0, k_lo, 1.0)), np.inf)
            parts.append((np.minimum(gm, lower) - self.gain_margin_db) * NEPER_PER_DB)
        if self.phase_margin_deg is not None or self.delay_margin is not None:
            pm, dm = batch.phase_and_delay_margins()
            if self.phase_margin_deg is not None:
                parts.append(np.radians(pm - self.phase_margin_deg))
            if self.delay_margin is not None:
                with np.errstate(divide="ignore"):
                    parts.append(np.where(dm > 0, np.log(np.where(dm > 0, dm, 1.0) / self.delay_margin), -np.inf))
        values = np.min(parts, axis=0)
        return with_unstable_rows(self, batch, values, also=np.isnan(values))

def closed_loop_unstable(loop: Loop) -> bool:
    """Whether ``loop`` has a closed-loop root in the closed right half-plane, by count (polynomial roots
    within a tolerance of the axis count; with a delay, the Nyquist count). A delayed loop whose return
    difference only comes within rounding of zero on the axis is flagged "marginal" by its stability row
    but is not counted here, so a requirement's set ends exactly where the count changes.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> G = Plant.from_string("10/((s-1)*(s+5))")
    >>> [closed_loop_unstable(Loop(G, Controller("P", {"kp": k}))) for k in (0.4, 0.5, 0.6)]
    [True, True, False]
    """
    return loop.stability().unstable_poles > 0


UNSTABLE_SLACK = -1.0
"""Slack of a margin-type requirement on a closed loop that is not stable (per unstable root): below any
met value, finite so that root bracketing over a parameter still brackets the stability boundary."""


def unstable_result(req: Requirement, loop: Loop, what: str, **details: Any) -> RequirementResult:
    """The result of a requirement that presumes a stable closed loop, on one that is not: not met,
    value ``nan``, the reason in the message (``what`` names the undefined quantity).

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("10/((s-1)*(s+5))"), Controller("P", {"kp": 0.5}))
    >>> r = unstable_result(MarginsRequirement(phase_margin_deg=45), loop, "phase margin")
    >>> r.met, r.message
    (False, 'closed loop marginally stable (a root on the imaginary axis at 0 rad/s): phase margin undefined, NOT met')
    """
    st = loop.stability()
    if st.marginal_frequency is not None:
        why = f"closed loop marginally stable (a root on the imaginary axis at {fmt(st.marginal_frequency)} rad/s)"
    elif st.neutral_gain is not None:
        why = f"closed loop UNSTABLE (|L(j inf)| = {fmt(st.neutral_gain)} >= 1 with a delay: neutral type)"
    elif st.method.startswith("not counted") or (st.near_axis is not None and st.unstable_poles == 0):
        why = "closed loop not certified stable (see its stability row)"
    elif st.near_axis is not None:
        why = (f"closed loop not stable in practice ({st.unstable_poles} root(s) within {fmt(st.near_axis)} of the "
               "imaginary axis)")
    else:
        why = f"closed loop UNSTABLE ({st.unstable_poles} root(s) in the closed right half-plane)"
    bound_field = next((f for f in req.bounds if getattr(req, f, None) is not None), None)
    bound = float(getattr(req, bound_field)) if bound_field else float("nan")
    unit = req.bounds[bound_field].unit if bound_field else ""
    return req.result(value=float("nan"), bound=bound, unit=unit, slack=UNSTABLE_SLACK * max(st.unstable_poles, 1),
                      margin=float("nan"), binding_frequency=st.marginal_frequency,
                      message=f"{why}: {what} undefined, NOT met",
                      **{**details, "closed_loop_stable": False, "unstable_roots": st.unstable_poles})


def with_unstable_rows(req: Requirement, batch: LoopBatch, values: np.ndarray,
                       also: np.ndarray | None = None) -> np.ndarray:
    """A batch slack whose closed-loop unstable loops carry the scalar verdict (:func:`unstable_result`:
    :data:`UNSTABLE_SLACK` per root counted by :meth:`~synth.loop_batch.LoopBatch.unstable_root_counts`): the
    vectorized margin and bandwidth formulas presume a stable closed loop. Stable rows marked in ``also``
    are evaluated one by one.

    Examples
    --------
    >>> from synth.loop_batch import LoopBatch; from synth.plant import Plant; from synth.controllers import Controller
    >>> batch = LoopBatch(Plant.from_string("10/((s-1)*(s+5))"), [Controller("P", {"kp": k}) for k in (0.4, 2.0)])
    >>> with_unstable_rows(MarginsRequirement(phase_margin_deg=45), batch, np.array([0.3, 0.3])).tolist()
    [-1.0, 0.3]
    """
    from synth.loop import Loop

    counts = batch.unstable_root_counts()
    values = np.array(values, dtype=float)
    values[counts > 0] = UNSTABLE_SLACK * counts[counts > 0]
    if also is not None:
        for i in np.flatnonzero(also & (counts == 0)):
            values[i] = req.slack(Loop(batch.plant, batch.controllers[i]))
    return values
