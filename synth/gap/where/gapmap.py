"""The gap map: one figure that says where a model and the hardware disagree.

Top: measured and model output with the residual below them, energy windows
shaded, the drift window hatched. Middle: the model-error model's magnitude
with its confidence band, the model's own magnitude for scale, significant
bands shaded. Bottom: residual RMS per regime bin relative to the rest of
the record (flagged bins in colour). The headline is the title.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from synth.gap.where.localize import GapLocalization
from synth.plant import Plant

__all__ = ["SHADE", "gap_map_figure", "write_gap_map"]

SHADE = "#f4a261"


def gap_map_figure(loc: GapLocalization, plant: Plant | None = None, max_regimes: int = 4) -> plt.Figure:
    """Draw the gap map of a :class:`~synth.gap.where.localize.GapLocalization`.

    Parameters
    ----------
    loc : GapLocalization
    plant : Plant, optional
        The model, drawn in the frequency panel for scale.
    max_regimes : int
        Regime variables shown (those with the largest flagged contrast first).

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.where.localize import localize_gap
    >>> t = np.arange(0, 10, 0.01)
    >>> u = np.where((t % 4) >= 2, 1.0, 0.0)
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> from synth.ident.simulate import simulate_plant
    >>> y = simulate_plant(Plant.from_string("1/(0.2*s+1)"), t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> fig = gap_map_figure(localize_gap(G, record_from_arrays(t, u, y)), G)
    >>> len(fig.axes)
    4
    >>> plt.close(fig)
    """
    r, where = loc.residual, loc.where
    fig = plt.figure(figsize=(10, 9.5))
    grid = fig.add_gridspec(4, 1, height_ratios=[2.2, 1.0, 2.0, 2.0], hspace=0.55)
    ax_y = fig.add_subplot(grid[0])
    ax_e = fig.add_subplot(grid[1], sharex=ax_y)
    ax_f = fig.add_subplot(grid[2])
    ax_r = fig.add_subplot(grid[3])
    ax_y.plot(r.t, r.y, color="0.2", lw=1.0, label="measured")
    ax_y.plot(r.t, r.y_model, color="tab:blue", lw=1.0, label="model")
    ax_e.plot(r.t, r.e, color="tab:red", lw=0.8)
    ax_e.axhline(0.0, color="0.5", lw=0.5)
    for w in where.time.windows:
        for ax in (ax_y, ax_e):
            ax.axvspan(w.t0, w.t1, color=SHADE, alpha=0.3, lw=0)
        ax_e.text(0.5 * (w.t0 + w.t1), ax_e.get_ylim()[1], f"{100 * w.share:.0f}%", ha="center", va="bottom",
                  fontsize=7, color="0.3")
    d = where.time.drift
    if d.detected:
        for ax in (ax_y, ax_e):
            ax.axvspan(d.t_start, d.t_end, facecolor="none", edgecolor="tab:purple", hatch="//", lw=0)
    ax_y.set_ylabel("output")
    ax_y.legend(loc="best", fontsize=8, frameon=False)
    ax_y.set_title("where in time: shaded = windows holding the residual energy (share)", fontsize=9, loc="left")
    ax_e.set_ylabel("residual")
    ax_e.set_xlabel("time [s]")
    plt.setp(ax_y.get_xticklabels(), visible=False)

    m = where.frequency.error_model
    mag = np.abs(m.response)
    ax_f.fill_between(m.w, np.maximum(m.mag_lo, 1e-300), m.mag_hi, color="tab:red", alpha=0.2, lw=0,
                      label=f"{100 * m.level:.0f} % confidence")
    ax_f.loglog(m.w, np.maximum(mag, 1e-12), color="tab:red", lw=1.2, label="error model |E|")
    if plant is not None:
        ax_f.loglog(m.w, np.abs(plant.freqresp(m.w)), color="tab:blue", lw=0.8, ls="--", label="model |G|")
    floor = float(np.min(mag[mag > 0])) / 10.0 if np.any(mag > 0) else 1e-12
    top = float(np.max(mag))
    if plant is not None:
        top = max(top, float(np.max(np.abs(plant.freqresp(m.w)))))
    ax_f.set_ylim(floor, 10.0 * top)  # an unexcited band's confidence region would swamp the scale
    for b in where.frequency.bands:
        ax_f.axvspan(b.w0, b.w1, color=SHADE, alpha=0.3, lw=0)
    ax_f.set_xlabel("frequency [rad/s]")
    ax_f.set_ylabel("magnitude")
    ax_f.legend(loc="best", fontsize=8, frameon=False)
    ax_f.set_title("where in frequency: shaded = error model significant and >= 10 % of |G|", fontsize=9, loc="left")

    regimes = sorted(where.regimes.values(), key=lambda v: -v.contrast)[:max_regimes]
    x, labels, colors, heights = 0.0, [], [], []
    ticks = []
    for v in regimes:
        for b in v.bins:
            heights.append(b.ratio)
            colors.append("tab:red" if b.flagged and b.ratio > 1 else ("tab:green" if b.flagged else "0.7"))
            labels.append(b.label)
            ticks.append(x)
            x += 1.0
        ax_r.text(ticks[-len(v.bins)] - 0.4, 0.97, v.name.replace("_", " "), fontsize=8, va="top",
                  fontweight="bold", transform=ax_r.get_xaxis_transform())
        x += 0.8
    if heights:
        ax_r.bar(ticks, heights, color=colors, width=0.8)
        ax_r.set_ylim(0.0, 1.2 * max(max(heights), 1.0))
        ax_r.set_xticks(ticks)
        ax_r.set_xticklabels(labels, rotation=35, ha="right", fontsize=7)
    ax_r.axhline(1.0, color="0.3", lw=0.8)
    ax_r.set_ylabel("RMS bin / rest")
    ax_r.set_title("where by regime: residual RMS per bin vs the rest (red/green = significantly larger/smaller)",
                   fontsize=9, loc="left")
    fig.suptitle(loc.headline, fontsize=10, wrap=True)
    return fig


def write_gap_map(loc: GapLocalization, path: str | Path, plant: Plant | None = None, dpi: int = 110) -> Path:
    """Draw the gap map and save it as PNG; returns the path.

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.where.localize import localize_gap
    >>> t = np.arange(0, 10, 0.01)
    >>> u = np.where((t % 4) >= 2, 1.0, 0.0)
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> y = u + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> p = write_gap_map(localize_gap(G, record_from_arrays(t, u, y)), pathlib.Path(tempfile.mkdtemp()) / "g.png", dpi=40)
    >>> p.stat().st_size > 5000
    True
    """
    path = Path(path)
    fig = gap_map_figure(loc, plant)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
