"""How close a stable loop comes to the critical point -1: the warning a feasible design carries when the
spec's requirements let it pass within a hair of instability."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.freqgrid import peak
from synth.loop import Loop
from synth.plant import Plant
from synth.polynomials import value_at_infinity
from synth.requirements.base import fmt
from synth.requirements.sensitivity import with_narrow_peaks

__all__ = ["NEAR_EDGE", "EdgeDistance", "edge_distance"]

NEAR_EDGE = 0.05
"""Smallest ``|1 + L(jw)|`` below which a design is reported as near the edge of stability (peak |S| above
26 dB: a 5 % change of the loop's response at that frequency, or a few degrees of phase, destabilizes it)."""


@dataclass
class EdgeDistance:
    """The smallest ``|1 + L(jw)|`` over the plants and frequencies, where it occurs and on what evidence.

    Attributes
    ----------
    distance : float
        ``min |1 + L(jw)|`` (``1 / peak |S|``); 0 when the loop has a root on the imaginary axis.
    frequency : float
        Where the minimum lies (rad/s).
    plant : str
        The plant it belongs to.
    per_decade : int
        Density of the log grid searched (each local minimum near the best then refined by golden section).
    frequency_range : tuple of float
        The band searched on that plant (rad/s): two decades beyond every corner of C, G and 1/delay.
    """

    distance: float
    frequency: float
    plant: str
    per_decade: int
    frequency_range: tuple[float, float]

    @property
    def near(self) -> bool:
        """True when the loop passes within :data:`NEAR_EDGE` of -1."""
        return self.distance < NEAR_EDGE

    @property
    def peak_sensitivity_db(self) -> float:
        """``20 log10(1 / distance)`` (inf at distance 0)."""
        return float(-20.0 * np.log10(self.distance)) if self.distance > 0 else float("inf")

    def warning(self) -> str:
        """A sentence for a design verdict when the loop is near the edge, else ``""``.

        Examples
        --------
        >>> EdgeDistance(0.2, 3.0, "G", 1600, (0.01, 100.0)).warning()
        ''
        >>> EdgeDistance(0.004, 3.0, "G", 1600, (0.01, 100.0)).warning()[:60]
        ' Warning: near the edge of stability. On G the loop passes w'
        """
        if not self.near:
            return ""
        return (f" Warning: near the edge of stability. On {self.plant} the loop passes within "
                f"{fmt(self.distance, 3)} of -1 at {fmt(self.frequency, 4)} rad/s (peak |S| "
                f"{fmt(self.peak_sensitivity_db, 3)} dB; log grid of {self.per_decade} points per decade over "
                f"[{fmt(self.frequency_range[0], 3)}, {fmt(self.frequency_range[1], 3)}] rad/s, minima refined): "
                f"a change of the loop's response by {fmt(100 * self.distance, 2)} % there destabilizes it. "
                "No requirement of the spec keeps it further from -1; add margins, disk_margin or a sensitivity "
                "peak bound to ask for more.")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict, with ``near`` and the threshold it was judged against."""
        out = asdict(self)
        out["frequency_range"] = list(self.frequency_range)
        out.update(near=self.near, threshold=NEAR_EDGE, peak_sensitivity_db=self.peak_sensitivity_db)
        return out


def edge_distance(plants: list[Plant], controller: Controller, per_decade: int = 1600) -> EdgeDistance:
    """Smallest ``|1 + L(jw)|`` over ``plants`` and ``w >= 0`` for a (stable) loop with ``controller``.

    Parameters
    ----------
    plants : list of Plant
    controller : Controller
    per_decade : int
        Log-grid density over each loop's frequency range (local minima within 3 dB of the deepest are refined
        by golden-section search, so the answer hardly depends on it).

    Returns
    -------
    EdgeDistance
        The worst plant's.

    Examples
    --------
    >>> g = Plant.from_string("1/(s*(s+1)*(s+2))")
    >>> e = edge_distance([g], Controller("P", {"kp": 5.9}))
    >>> round(e.distance, 4), round(e.frequency, 3), e.near  # L crosses the real axis at -5.9/6, 1/60 from -1
    (0.0072, 1.405, True)
    """
    worst: EdgeDistance | None = None
    for i, plant in enumerate(plants):
        loop = Loop(plant, controller)
        # the loop's narrow peaks added: a closed-loop mode of damping 1e-5 passes 0.05 from -1 within 0.01 rad/s
        # of 1000 rad/s, between two points 1.4 rad/s apart (found by a black-box test)
        grid = with_narrow_peaks(np.concatenate([[0.0], loop.grid(per_decade)]), loop, (0.0, np.inf))
        peak_s, w = peak(lambda x, loop=loop: np.abs(loop.S(x)), grid)
        distance = 0.0 if not np.isfinite(peak_s) else (1.0 / peak_s if peak_s > 0 else float("inf"))
        at_infinity = _distance_at_infinity(loop)
        if at_infinity < distance:  # the loop approaches -1 beyond the searched band (biproper, or L -> 0 from inside)
            distance, w = at_infinity, float("inf")
        here = EdgeDistance(float(distance), float(w), plant.label or f"plant {i + 1}", per_decade,
                            (float(grid[1]), float(grid[-1])))
        if worst is None or here.distance < worst.distance:
            worst = here
    assert worst is not None, "edge_distance needs at least one plant"
    return worst


def _distance_at_infinity(loop: Loop) -> float:
    """``inf |1 + L(jw)|`` as ``w -> inf``: 1 for a strictly proper loop; ``|1 + k|`` for a biproper one with
    high-frequency gain ``k``, ``|1 - |k||`` when a delay turns ``k`` round the circle.

    Examples
    --------
    >>> g = Plant.from_string("(s+2)/(s+1)", delay=0.1)
    >>> _distance_at_infinity(Loop(g, Controller("P", {"kp": 0.5})))
    0.5
    """
    k = value_at_infinity(loop.num, loop.den)  # 0 strictly proper; inf improper (an unfiltered derivative)
    if not np.isfinite(k):
        return float("inf")
    return float(abs(1.0 - abs(k)) if loop.delay > 0 else abs(1.0 + k))
