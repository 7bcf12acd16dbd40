"""Report figures (matplotlib, Agg backend, PNG).

Every figure function takes plain data and a path and returns the path; none
of them computes a requirement (the numbers come from the result).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

__all__ = [
    "COLORS",
    "bode_with_slew_bound",
    "bound_drawn",
    "delay_chart",
    "gain_set_plot",
    "sensitivity_plot",
    "step_plot",
    "warm_up",
]

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from synth.figure_files import save_figure
from synth.freqgrid import log_grid
from synth.loop import Loop
from synth.requirements import Sensitivity, SlewRate, StaticSensitivity, StepResponse
from synth.requirements.sensitivity import PeakSensitivity
from synth.settled_step import settled_step
from synth.timeresp import step_response

COLORS = ["#1f4e9c", "#c0392b", "#2e8b57", "#8e44ad", "#d35400"]



def _db(x: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return 20 * np.log10(np.abs(x))


def _range(loops: list[tuple[str, Loop]], extra: list[float]) -> np.ndarray:
    lo = min(loop.frequency_range[0] for _, loop in loops)
    hi = max(loop.frequency_range[1] for _, loop in loops)
    if extra:
        lo, hi = min(lo, min(extra) / 3), max(hi, max(extra) * 3)
    return log_grid(lo, hi, 100)


def bode_with_slew_bound(loops: list[tuple[str, Loop]], slew: list[SlewRate], path: Path,
                         drawn: list[dict[str, Any]] | None = None) -> Path:
    """Open-loop plant and compensated loop magnitudes with the slew-rate bound of eq. 12.

    ``drawn``, if given, receives one entry per bound drawn (see :func:`bound_drawn`).
    """
    extra = [w for r in slew for w in r.band]
    w = _range(loops, extra)
    fig, ax = plt.subplots(figsize=(8, 4.8))
    plant = loops[0][1].plant
    ax.semilogx(w, _db(plant.freqresp(w)), color="#3b7dd8", lw=1.5, label="open-loop plant |G|")
    for i, (name, loop) in enumerate(loops):
        ax.semilogx(w, _db(loop.L(w)), color=["black", "#555555", "#999999"][i % 3],
                    ls=["-", "--", ":"][i % 3], lw=1.8, label=f"compensated |C G|, {name}")
    for j, r in enumerate(slew):
        bound = r.rate_limit / r.max_error * np.abs(plant.freqresp(w)) / w
        (line,) = ax.semilogx(w, _db(bound), color="#c0392b", lw=1.6,
                              label=f"rate bound B|G|/(De w), B/De = {r.rate_limit / r.max_error:.4g} 1/s")
        ax.axvspan(*r.band, color="#c0392b", alpha=0.06 if j == 0 else 0.03)
        if drawn is not None:
            drawn.append(bound_drawn(line, r.name(), "slew-rate Bode bound B|G|/(De w) [dB]"))
    ax.set_xlabel("frequency [rad/s]")
    ax.set_ylabel("magnitude [dB]")
    ax.set_title("Compensated loop against the slew-rate bound (seed eq. 12); shaded: bound's band")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower left")
    return save_figure(fig, path)


def bound_drawn(artist: Any, requirement: str, what: str) -> dict[str, Any]:
    """What a drawn bound covers, read back from the matplotlib artist: its requirement, the x range and the
    y range of the artist's data (for a horizontal bound both y ends are the bound).

    Examples
    --------
    >>> fig, ax = plt.subplots(); lines = ax.hlines(-15.0, 0.01, 30.0)
    >>> bound_drawn(lines, "sensitivity", "|S| bound [dB]")
    {'requirement': 'sensitivity', 'what': '|S| bound [dB]', 'x': [0.01, 30.0], 'y': [-15.0, -15.0]}
    >>> plt.close(fig)
    """
    if hasattr(artist, "get_segments"):
        xy = np.concatenate([np.asarray(s, float) for s in artist.get_segments()])
    else:
        xy = np.asarray(artist.get_xydata(), float)
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    return {"requirement": requirement, "what": what,
            "x": [float(f"{xy[:, 0].min():.6g}"), float(f"{xy[:, 0].max():.6g}")],
            "y": [float(f"{xy[:, 1].min():.6g}"), float(f"{xy[:, 1].max():.6g}")]}


def sensitivity_plot(loops: list[tuple[str, Loop]], requirements: list[Any], path: Path,
                     drawn: list[dict[str, Any]] | None = None) -> Path:
    """|S| in dB with every sensitivity bound drawn: a band's bound over its band, the static (DC) bound over the
    lowest decade shown, the peak bound across the plot.

    ``drawn``, if given, receives one entry per bound drawn, read back from the artists (:func:`bound_drawn`).
    """
    bands = [w for r in requirements if isinstance(r, Sensitivity) for w in r.band if w > 0]
    w = _range(loops, bands)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i, (name, loop) in enumerate(loops):
        ax.semilogx(w, _db(loop.S(w)), color=COLORS[i % len(COLORS)], lw=1.8, label=f"|S|, {name}")
    found = []
    for r in requirements:
        if isinstance(r, Sensitivity):
            lo = r.band[0] if r.band[0] > 0 else w[0]
            artist = ax.hlines(r.max_db, lo, r.band[1], color="#c0392b", lw=2.5,
                               label=f"bound {r.max_db:g} dB, {r.band[0]:g}-{r.band[1]:g} rad/s")
            found.append((artist, r.name(), "|S| bound over its band [dB]"))
        elif isinstance(r, StaticSensitivity):
            gain = f"plant gain {r.plant_gain:g}" if r.plant_gain else "the plant's DC gain"
            artist = ax.hlines(r.max_db, w[0], 10 * w[0], color="#c0392b", lw=2.5, linestyles="dashed",
                               label=f"static bound {r.max_db:g} dB on S(0) with {gain} (drawn over the lowest decade)")
            ax.plot([w[0]], [r.max_db], marker="v", color="#c0392b", ms=10, ls="none")
            found.append((artist, r.name(), "static |S(0)| bound [dB]"))
            if r.plant_gain:  # the requirement's own |S(0)|, with its stated gain (the curves use the model's)
                for i, (name, loop) in enumerate(loops):
                    value = r.evaluate(loop).value
                    if np.isfinite(value):
                        ax.plot([w[0]], [value], marker="o", color=COLORS[i % len(COLORS)], ms=7, ls="none",
                                label=f"|S(0)| with {gain}, {name}: {value:.4g} dB")
        elif isinstance(r, PeakSensitivity):
            artist = ax.hlines(r.max_db, w[0], w[-1], color="#8e44ad", linestyles="dashed", lw=1.2,
                               label=f"peak |S| bound {r.max_db:g} dB")
            found.append((artist, r.name(), "peak |S| bound [dB]"))
    if drawn is not None:
        drawn.extend(bound_drawn(artist, name, what) for artist, name, what in found)
    ax.axhline(0, color="grey", lw=0.8)
    ax.set_xlabel("frequency [rad/s]")
    ax.set_ylabel("|S| [dB]")
    ax.set_title("Sensitivity: disturbance attenuation (below 0 dB) and amplification")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return save_figure(fig, path)


def step_plot(loops: list[tuple[str, Loop]], path: Path, scale: float = 1.0, unit: str = "",
              t_end: float | None = None, open_loop: bool = True, requirements: Sequence[Any] = (),
              drawn: list[dict[str, Any]] | None = None) -> Path:
    """Closed-loop responses to a reference step of size ``scale`` (and the plant's open-loop step), with the
    limits of every linear ``step_response`` requirement drawn about the first loop's final value: the
    overshoot limit as a line, the settling band from the settling-time limit on, the rise-time limit as a
    segment of that length from where the first loop passes 10 %.

    ``drawn``, if given, receives one entry per limit drawn (:func:`bound_drawn`).
    """
    limits = [r for r in requirements if isinstance(r, StepResponse) and r.under != "simulation"]
    fig, ax = plt.subplots(figsize=(8, 4.2))
    horizon = t_end if t_end is not None else max(float(settled_step(loop)[0][-1]) for _, loop in loops)
    if t_end is None:
        horizon = max([horizon] + [1.25 * r.max_settling_time for r in limits if r.max_settling_time is not None])
    first: tuple[np.ndarray, np.ndarray] | None = None
    for i, (name, loop) in enumerate(loops):
        t, y, dt = step_response(loop, horizon)
        first = first or (t, scale * y)
        extra = f" (sampled, dt = {dt:.2g} s)" if dt else ""
        ax.plot(t, scale * y, color=COLORS[i % len(COLORS)], lw=1.8, label=f"closed loop, {name}{extra}")
    if open_loop:
        from synth.exact_steps import exact_step

        plant = loops[0][1].plant
        t = np.linspace(0, horizon, 2001)
        y = exact_step(plant.num, plant.den, t)
        shift = np.clip(t - plant.delay, 0, None)
        y = np.interp(shift, t, y) * (t >= plant.delay)
        ax.plot(t, scale * y / max(plant.dc_gain(), 1e-300), color="grey", ls=":", lw=1.5,
                label="open-loop plant, normalized to its DC gain")
    found = _step_limits(ax, limits, scale * loops[0][1].dc_gain(), horizon, first) if limits and first else []
    if drawn is not None:
        drawn.extend(bound_drawn(artist, name, what) for artist, name, what in found)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"output [{unit}]" if unit else "output per unit reference step")
    ax.set_title("Linear step response (reference step)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return save_figure(fig, path)


def _step_limits(ax: Any, limits: list[Any], final: float, horizon: float,
                 first: tuple[np.ndarray, np.ndarray]) -> list[tuple[Any, str, str]]:
    """Draw each step limit about ``final`` (the first loop's final value); ``(artist, requirement, what)``."""
    found = []
    for r in limits:
        if r.max_overshoot is not None:
            level = final * (1.0 + r.max_overshoot / 100.0)
            artist = ax.hlines(level, 0.0, horizon, color="#c0392b", lw=2.0,
                               label=f"overshoot limit {r.max_overshoot:g} % (of the design's final value)")
            found.append((artist, r.name(), "overshoot limit [output]"))
        if r.max_settling_time is not None and r.max_settling_time < horizon:
            band = abs(final) * r.settle_band
            artist = ax.hlines([final - band, final + band], r.max_settling_time, horizon, color="#8e44ad",
                               linestyles="dashed", lw=1.4,
                               label=f"settled within +-{100 * r.settle_band:g} % from {r.max_settling_time:g} s on")
            found.append((artist, r.name(), "settling band from the settling-time limit [s, output]"))
        if r.max_rise_time is not None:
            t, y = first
            passed = y * np.sign(final) >= 0.1 * abs(final)  # the first loop past 10 % of its final value
            start = float(t[np.argmax(passed)]) if np.any(passed) else 0.0
            artist = ax.hlines(0.5 * final, start, start + r.max_rise_time, color="#16a085", lw=2.5,
                               label=f"rise-time limit {r.max_rise_time:g} s (10-90 %), from the design's 10 % time")
            found.append((artist, r.name(), "rise-time limit from the 10 % time [s]"))
    return found


def gain_set_plot(parameter: str, bounds: tuple[float, float], curves: dict[str, tuple[np.ndarray, np.ndarray]],
                  intervals: list[list[float]], marks: dict[str, float], path: Path) -> Path:
    """Each requirement's slack against the parameter, feasible intervals shaded."""
    fig, ax = plt.subplots(figsize=(8, 4.2))
    for i, (name, (x, y)) in enumerate(curves.items()):
        finite = np.isfinite(y)
        ax.plot(x[finite], np.clip(y[finite], -3, 3), lw=1.8, color=COLORS[i % len(COLORS)], label=name)
    for lo, hi in intervals:
        ax.axvspan(lo, hi, color="#2e8b57", alpha=0.12)
    for j, (label, value) in enumerate(marks.items()):
        ax.axvline(value, color="black", ls=["-", "--", ":"][j % 3], lw=1.2, label=label)
    ax.axhline(0, color="grey", lw=1)
    pad = 0.02 * (bounds[1] - bounds[0])
    ax.set_xlim(bounds[0] - pad, bounds[1] + pad)
    ax.set_xlabel(parameter)
    ax.set_ylabel("slack [Np], >= 0 met (clipped at +-3)")
    ax.set_title(f"Feasible {parameter} (shaded): every requirement's slack")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return save_figure(fig, path)


def delay_chart(rows: list[dict[str, Any]], marks: dict[str, float], path: Path) -> Path:
    """Critical proportional gain against the in-loop delay."""
    fig, ax = plt.subplots(figsize=(7, 3.8))
    d = np.array([r["delay"] for r in rows]) * 1e3
    k = np.array([r["critical_gain"] for r in rows], float)
    finite = np.isfinite(k)
    ax.semilogy(d[finite], k[finite], "o-", color=COLORS[0], label="critical gain (loop turns unstable)")
    low = np.array([r.get("lowest_gain") or 0.0 for r in rows], float)
    if np.any(low > 0):  # an open-loop unstable plant: gains below these leave it unstable too
        ax.semilogy(d[low > 0], low[low > 0], "s--", color=COLORS[1], label="lowest stabilizing gain")
    for j, (label, value) in enumerate(marks.items()):
        ax.axhline(value, color="black", ls=["-", "--", ":"][j % 3], lw=1.2, label=label)
    ax.set_xlabel("in-loop delay [ms]")
    ax.set_ylabel("gain")
    ax.set_title("Which gains stay stable if the delay is inside the loop")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path)


def warm_up() -> None:
    """Draw one log-log figure into memory: matplotlib's font lookup and text layout are set up once, here
    rather than in the report's first figure (the design command does this on one core while the design runs on
    the other).

    Examples
    --------
    >>> warm_up()
    """
    import io

    from synth.figure_files import DPI, plain_log_tick_labels

    # drawn as the report's figures are (save_figure's tick labels, at their dpi): the report's figures are drawn
    # in this process or in a child forked from it
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog([1e-6, 1e8], [1e-6, 1e8], label="x")
    ax.set_xlabel("x [rad/s]")
    ax.legend()
    plain_log_tick_labels(fig)
    fig.set_dpi(DPI)
    fig.tight_layout()
    fig.set_layout_engine(None)  # as figure_files.save_figure: one draw, not two
    fig.savefig(io.BytesIO(), format="png", dpi=DPI)
    plt.close(fig)
