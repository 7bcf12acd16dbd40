"""Figure of a disturbance spectrum: PSD in dB against log frequency with trend, floor, spikes, share.

Draws only what :class:`synth.ident.psd.PsdAnalysis` holds.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from synth.figure_files import save_figure
from synth.ident.psd import PsdAnalysis
from synth.ident.welch import unit_squared

__all__ = ["psd_plot"]


def psd_plot(a: PsdAnalysis, path: str | Path, title: str = "") -> Path:
    """PSD [dB re 1 unit^2/(rad/s)] on a log frequency axis, with the analysis marked on it.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from synth.ident.psd import analyze_psd
    >>> a = analyze_psd([np.random.default_rng(0).normal(size=8000)], 0.001)
    >>> psd_plot(a, pathlib.Path(tempfile.mkdtemp()) / "psd.png").suffix
    '.png'
    """
    path = Path(path)
    u = f"{unit_squared(a.unit)}/(rad/s)"
    fig, ax = plt.subplots(figsize=(8.5, 5.2))
    ax.semilogx(a.w, a.psd_db, color="#1f4e9c", lw=0.8, label=f"Welch PSD ({a.records} record(s), {a.segments} segments)")
    ax.axhline(a.floor_db, color="#7f8c8d", ls="--", lw=1.2,
               label=f"noise floor {a.floor_db:.1f} dB ({a.floor_source})")
    if a.trend is not None:
        xs = np.logspace(np.log10(a.trend.band[0]), np.log10(a.trend.band[1]), 50)
        ax.semilogx(xs, a.trend.value_db(xs), color="#c0392b", lw=2,
                    label=f"trend {a.trend.slope_db_per_decade:+.1f} dB/decade")
    for i, s in enumerate(a.spikes):
        ax.plot([s.w], [s.level_db], "v", color="#d35400", ms=7,
                label="spikes (> running median)" if i == 0 else None)
        if i < 8:
            ax.annotate(f"{s.w:.0f}", (s.w, s.level_db), textcoords="offset points", xytext=(0, 6), ha="center",
                        fontsize=7, color="#d35400")
    if a.share_frequency is not None:
        ax.axvline(a.share_frequency, color="#2e8b57", lw=1.5,
                   label=f"{100 * a.share:g} % of disturbance power below {a.share_frequency:.3g} rad/s")
    ax.set_xlabel("frequency [rad/s]")
    ax.set_ylabel(f"PSD [dB re 1 {u}]")
    top = float(np.max(a.psd_db))
    ax.set_ylim(min(a.floor_db - 15, float(np.percentile(a.psd_db, 1)) - 3), top + 5)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    if title:
        ax.set_title(title, fontsize=10)
    return save_figure(fig, path)
