"""Delay margin: the loop stays stable for any extra in-loop delay up to a bound."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import PositiveFloat

from synth.errors import ModelError
from synth.polynomials import value_at_infinity
from synth.requirements.base import Bound, Requirement, RequirementResult, fmt, register
from synth.requirements.margins import closed_loop_unstable, unstable_result, with_unstable_rows
from synth.stability import closed_loop_stability, neutral_with_any_delay

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = ["DelayMargin", "delay_margins_per_crossover"]


def delay_margins_per_crossover(loop: Loop) -> list[tuple[float, float, float]]:
    """``(wc, phase margin in (0, 360] deg, delay margin)`` at every gain crossover of ``loop``.

    An extra delay ``tau`` turns ``L(j wc)`` clockwise by ``wc tau`` and leaves ``|L|`` unchanged, so a
    closed-loop root reaches the imaginary axis first at ``min PM/wc`` over the crossovers: that
    minimum is the exact delay margin of a stable loop.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> [(round(w, 3), round(pm, 2), round(dm, 5)) for w, pm, dm in delay_margins_per_crossover(
    ...     Loop(Plant.from_string("1/s"), Controller("P", {"kp": 2.0})))]
    [(2.0, 90.0, 0.7854)]
    """
    out = []
    for wc in loop.gain_crossovers():
        phase = float(np.degrees(np.angle(loop.L(np.array([wc]))[0])))
        pm = (phase + 180.0) % 360.0
        pm = 360.0 if pm == 0.0 and phase != -180.0 else pm
        out.append((float(wc), pm, float(np.radians(pm) / wc)))
    return out


@register
class DelayMargin(Requirement):
    """The closed loop stays stable for every extra in-loop delay from 0 up to ``min`` seconds.

    Exact: the delay margin of a stable loop is the minimum over its gain crossovers of ``PM/wc``
    (:func:`delay_margins_per_crossover`); the Nyquist count with the bound's delay added
    (:func:`synth.stability.closed_loop_stability`) is reported beside it as a second, independent
    verdict, and a disagreement between the two is reported as undetermined (not met). On a closed loop
    that is not stable the requirement is not met.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
    >>> r = DelayMargin(min=0.02).evaluate(Loop(G, Controller("P", {"kp": 3.0})))
    >>> r.met, round(r.value * 1e3, 2), r.details["nyquist_stable_at_bound"]
    (True, 25.06, True)
    >>> DelayMargin(min=0.02).evaluate(Loop(G, Controller("P", {"kp": 5.0}))).met
    False
    """

    type: Literal["delay_margin"] = "delay_margin"
    min: PositiveFloat
    title: ClassVar[str] = "delay margin"
    bounds: ClassVar[dict[str, Bound]] = {"min": Bound("lower", "s")}
    example: ClassVar[dict[str, Any]] = {"type": "delay_margin", "min": 0.01}

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        if closed_loop_unstable(loop):
            return unstable_result(self, loop, "delay margin")
        per_crossover = delay_margins_per_crossover(loop)
        dm, wc = min(((d, w) for w, _, d in per_crossover), default=(np.inf, None))
        neutral = neutral_with_any_delay(loop.num, loop.den)
        if neutral:  # any added delay: infinitely many roots at Re s = ln|L(j inf)|/delay >= 0
            dm, wc = 0.0, None
        slack = float(np.log(dm / self.min)) if dm > 0 else -np.inf
        try:
            nyquist = closed_loop_stability(loop.num, loop.den, loop.delay + self.min).stable
        except ModelError:
            nyquist = None
        agree = nyquist is None or abs(slack) <= 1e-6 or nyquist == (slack > 0)
        verdict = "met" if slack >= 0 else "NOT met"
        if not agree:
            verdict, slack = "undetermined (the crossover formula and the Nyquist count disagree): NOT met", -abs(slack)
        crossings = ", ".join(f"PM {fmt(pm)} deg at {fmt(w)} rad/s" for w, pm, _ in per_crossover) or "no crossover"
        check = "" if nyquist is None else (
            f"; Nyquist count with {fmt(self.min * 1e3)} ms added: {'stable' if nyquist else 'UNSTABLE'}")
        if neutral:
            agree, verdict = True, "NOT met"
            l_inf = abs(value_at_infinity(loop.num, loop.den))
            msg = (f"delay margin 0 ms >= {fmt(self.min * 1e3)} ms: NOT met (|L(j inf)| = {fmt(l_inf)} >= 1: any "
                   "added delay makes the loop neutral-type unstable, infinitely many roots in the right half-plane)")
        else:
            msg = (f"delay margin {fmt(dm * 1e3)} ms >= {fmt(self.min * 1e3)} ms: {verdict} "
                   f"(exact: min over {len(per_crossover)} crossover(s) of PM/wc; {crossings}{check})")
        return self.result(value=dm, bound=self.min, unit="s", slack=slack, margin=dm - self.min,
                           binding_frequency=wc, message=msg, method="min over gain crossovers of PM/wc",
                           crossovers=[{"frequency": w, "phase_margin_deg": pm, "delay_margin": d}
                                       for w, pm, d in per_crossover],
                           nyquist_stable_at_bound=nyquist, determined=agree)

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack: every loop's gain crossovers at once (batched polynomial roots), ``PM/wc``
        with the phase margin in ``(0, 360]`` deg as :func:`delay_margins_per_crossover` takes it; unstable
        rows carry the scalar verdict (the Nyquist cross-check runs where the exact slack is evaluated).

        Examples
        --------
        >>> from synth.loop import Loop; from synth.loop_batch import LoopBatch
        >>> from synth.plant import Plant; from synth.controllers import Controller
        >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
        >>> batch = LoopBatch(G, [Controller("P", {"kp": k}) for k in (1.0, 3.0, 5.0)])
        >>> req = DelayMargin(min=0.02)
        >>> bool(np.allclose(req.batch_slack(batch), [req.slack(Loop(G, c)) for c in batch.controllers]))
        True
        """
        _, dm = batch.phase_and_delay_margins()  # 0 where |L(j inf)| >= 1, as the scalar form
        with np.errstate(divide="ignore"):
            values = np.where(dm > 0, np.log(np.where(dm > 0, dm, 1.0) / self.min), -np.inf)
        return with_unstable_rows(self, batch, values)
