"""Figures of the nonlinear simulation (matplotlib, Agg backend, PNG).

Each function takes results and a path and returns the path; none of them
computes anything the JSON does not hold (the time series come from the runs).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from synth.figure_files import save_figure
from synth.sim.results import SimResult

__all__ = ["COLORS", "onset_chart", "rise_vs_rate_chart", "step_comparison"]

COLORS = ["#1f4e9c", "#c0392b", "#2e8b57", "#8e44ad", "#d35400", "#7f8c8d"]



SHOWN_LIMIT = 1e12
"""Values beyond this magnitude (a diverging run, up to overflow) are left out of the figures."""


def _shown(x: np.ndarray) -> np.ndarray:
    return np.where(np.abs(x) < SHOWN_LIMIT, x, np.nan)


def step_comparison(runs: dict[str, dict[str, SimResult]], path: Path, units: dict[str, str],
                    t_end: float | None = None) -> Path:
    """Linear and nonlinear step responses side by side (output above, actuator below).

    Parameters
    ----------
    runs : dict
        ``{label: {"nonlinear": SimResult, "linear": SimResult}}``.
    path : Path
    units : dict
        ``{"input": ..., "output": ...}``.
    t_end : float, optional
        Right end of the time axis (s).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.loops import NonlinearLoop
    >>> from synth.sim.simulator import simulate_step
    >>> from synth.sim.blocks import Saturation
    >>> loop = NonlinearLoop(Plant.from_string("10/(s+10)"), Controller("P", {"kp": 2}),
    ...                      actuator=[Saturation(-1, 1)])
    >>> runs = {"P(2)": {"nonlinear": simulate_step(loop, 0, 1, 0.5),
    ...                  "linear": simulate_step(loop.linear(), 0, 1, 0.5)}}
    >>> step_comparison(runs, pathlib.Path(tempfile.mkdtemp()) / "s.png", {"input": "V", "output": "m"}).suffix
    '.png'
    """
    fig, (ax_y, ax_u) = plt.subplots(2, 1, figsize=(8, 6.2), sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    for i, (label, pair) in enumerate(runs.items()):
        color = COLORS[i % len(COLORS)]
        nl, lin = pair["nonlinear"], pair["linear"]
        ax_y.plot(lin.t, _shown(lin.output), color=color, ls="--", lw=1.3, label=f"{label}, every nonlinear block off")
        ax_y.plot(nl.t, _shown(nl.output), color=color, lw=1.8, label=f"{label}, nonlinear")
        ax_u.plot(lin.t, _shown(lin.actuator), color=color, ls="--", lw=1.1,
                  label=f"{label}, linear (peaks at {np.max(np.abs(lin.actuator)):.4g})")
        ax_u.plot(nl.t, _shown(nl.actuator), color=color, lw=1.5, label=f"{label}")
        limited = nl.active("rate_limited") | nl.active("saturated")
        if np.any(limited):
            ax_u.fill_between(nl.t, 0, 1, where=limited, transform=ax_u.get_xaxis_transform(), color=color,
                              alpha=0.08, step="mid")
    first = next(iter(runs.values()))["nonlinear"]
    ax_y.plot(first.t, first.reference, color="grey", lw=1, ls=":", label="reference")
    ax_y.set_ylabel(f"output [{units.get('output', '')}]")
    ax_y.set_title("Step response: nonlinear loop (solid) and every nonlinear block off (dashed)")
    ax_y.grid(True, alpha=0.3)
    ax_y.legend(fontsize=8, loc="lower right")
    ax_u.set_ylabel(f"actuator [{units.get('input', '')}]")
    ax_u.set_xlabel("time [s]")
    ax_u.set_title("Actuator output (shaded: a rate limit or saturation is active)", fontsize=10)
    ax_u.grid(True, alpha=0.3)
    ax_u.legend(fontsize=7, loc="upper right")
    nl_all = np.concatenate([p["nonlinear"].actuator for p in runs.values()])
    nl_all = _shown(nl_all)
    if np.all(np.isfinite(nl_all)):  # a diverging run's axis is matplotlib's own
        lo, hi = float(np.min(nl_all)), float(np.max(nl_all))
        pad = 0.25 * (hi - lo) if hi > lo else 1.0
        ax_u.set_ylim(lo - pad, hi + pad)  # linear actuator signals may run far outside: see the legend
    if t_end is not None:
        ax_u.set_xlim(first.t[0], t_end)
    return save_figure(fig, path)


def onset_chart(onset: dict[str, Any], continuous: list[dict[str, Any]], marks: dict[str, float], path: Path,
                published_gain: float | None = None) -> Path:
    """Gain at which oscillation starts against the in-loop delay, one line per actuator variant.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> rows = [{"delay": d, "variant": "linear", "onset_gain": g} for d, g in ((0.01, 6.0), (0.02, 3.4))]
    >>> onset_chart({"rows": rows, "gains": [0.5, 50]}, [], {"P(3)": 3.0},
    ...             pathlib.Path(tempfile.mkdtemp()) / "o.png").suffix
    '.png'
    """
    fig, ax = plt.subplots(figsize=(8, 4.6))
    variants = list(dict.fromkeys(r["variant"] for r in onset["rows"]))
    top = onset["gains"][1]
    for i, v in enumerate(variants):
        rows = [r for r in onset["rows"] if r["variant"] == v]
        d = np.array([r["delay"] for r in rows]) * 1e3
        k = np.array([r["onset_gain"] if r["onset_gain"] is not None else np.nan for r in rows], float)
        ax.semilogy(d, k, marker="o", ms=4, lw=1.6, color=COLORS[i % len(COLORS)], label=f"simulated, {v}")
        none = np.isnan(k)
        if np.any(none):
            ax.plot(d[none], np.full(none.sum(), top), marker="^", ls="none", color=COLORS[i % len(COLORS)])
    if continuous:
        d = np.array([r["delay"] for r in continuous]) * 1e3
        k = np.array([float(r["critical_gain"]) for r in continuous])
        ok = np.isfinite(k)
        ax.semilogy(d[ok], k[ok], color="black", ls=":", lw=1.4, label="continuous linear model (exact)")
    for j, (label, value) in enumerate(marks.items()):
        ax.axhline(value, color="black", ls=["-", "--"][j % 2], lw=1.0, label=label)
    if published_gain is not None:
        ax.axhline(published_gain, color="#f0b400", lw=2.5, alpha=0.8,
                   label=f"source: limit cycles above K = {published_gain:g}")
    ax.set_xlabel("in-loop delay [ms]")
    ax.set_ylabel("gain at which oscillation starts")
    ax.set_title("Onset of sustained oscillation (triangles: none up to the top of the range)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    return save_figure(fig, path)


def rise_vs_rate_chart(sweep: dict[str, Any], unit: str, path: Path) -> Path:
    """Rise time at one gain against the rate limit, with the published rise time.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> sweep = {"rates": [1e3, 1e4, 1e5], "rise_times": [0.2, 0.05, 0.03], "gain": 3, "published": 0.05,
    ...          "specified": 1e4}
    >>> rise_vs_rate_chart(sweep, "PWM", pathlib.Path(tempfile.mkdtemp()) / "r.png").suffix
    '.png'
    """
    fig, ax = plt.subplots(figsize=(7, 3.8))
    ax.semilogx(sweep["rates"], sweep["rise_times"], "o-", ms=3, color=COLORS[0],
                label=f"simulated rise time at K = {sweep['gain']:g}")
    ax.axhline(sweep["published"], color="#f0b400", lw=2.5, alpha=0.8, label="source: measured rise time")
    ax.axvline(sweep["specified"], color="black", ls="--", lw=1.0, label="rate limit in the spec")
    ax.set_xlabel(f"rate limit [{unit}/s]")
    ax.set_ylabel("rise time 10-90 % [s]")
    ax.set_title("Which rate limit reproduces the measured rise time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path)
