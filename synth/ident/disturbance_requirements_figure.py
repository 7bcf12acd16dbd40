"""Figure of a disturbance spectrum with the requirements read from it: floors, fitted shape, spikes, band."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from synth.figure_files import save_figure
from synth.ident.disturbance_requirements import DisturbanceRequirements
from synth.ident.psd import PsdAnalysis
from synth.ident.welch import unit_squared

__all__ = ["disturbance_requirements_plot"]


def disturbance_requirements_plot(a: PsdAnalysis, r: DisturbanceRequirements, path: str | Path,
                                  title: str = "") -> Path:
    """PSD [dB] on a log frequency axis with the measured and sensor floors, the fitted plateau and decay,
    the spikes, the sensitivity band shaded, and the bandwidth floor and ideal bandwidth drawn.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from synth.ident.disturbance_synthetic import synthetic_disturbance_record
    >>> from synth.ident.disturbance_requirements import requirements_from_records
    >>> a, r = requirements_from_records([synthetic_disturbance_record(duration=20.0)])
    >>> disturbance_requirements_plot(a, r, pathlib.Path(tempfile.mkdtemp()) / "d.png").suffix
    '.png'
    """
    u = f"{unit_squared(a.unit)}/(rad/s)"
    fig, ax = plt.subplots(figsize=(8.5, 5.2))
    ax.semilogx(a.w, a.psd_db, color="#1f4e9c", lw=0.7, label=f"Welch PSD ({a.records} record(s))")
    ax.axhline(a.floor_db, color="#7f8c8d", ls="--", lw=1.0, label=f"measured floor {a.floor_db:.1f} dB ({a.floor_source})")
    ax.axhline(r.sensor_floor_db, color="black", ls=":", lw=1.2,
               label=f"sensor floor {r.sensor_floor_db:.1f} dB ({r.sensor_floor_source})")
    xs = np.logspace(np.log10(a.w[0]), np.log10(a.w[-1]), 400)
    line = 10 * np.log10(10 ** (r.fit.value_db(xs) / 10) + a.floor)
    ax.semilogx(xs, line, color="#c0392b", lw=2,
                label=f"fit: plateau {r.fit.plateau_db:.1f} dB to {r.fit.corner:.3g} rad/s, "
                      f"{r.fit.slope_db_per_decade:+.1f} dB/decade")
    for i, s in enumerate(a.spikes):
        ax.plot([s.w], [s.level_db], "v", color="#d35400", ms=7, label="spikes (notch, not bandwidth)" if i == 0 else None)
    if r.max_db is not None:
        ax.axvspan(a.w[0], r.band[1], color="#2e8b57", alpha=0.12,
                   label=f"sensitivity <= {r.max_db:.3g} dB below {r.band[1]:.3g} rad/s")
    if r.min_bandwidth is not None:
        ax.axvline(r.min_bandwidth, color="#8e44ad", lw=1.5, label=f"bandwidth floor {r.min_bandwidth:.3g} rad/s "
                   f"({r.margin_db:g} dB above the sensor floor)")
    if r.ideal_bandwidth is not None:
        ax.axvline(r.ideal_bandwidth, color="#8e44ad", lw=1.0, ls="--",
                   label=f"disturbance meets the sensor floor {r.ideal_bandwidth:.3g} rad/s")
    ax.set_xlabel("frequency [rad/s]")
    ax.set_ylabel(f"PSD [dB re 1 {u}]")
    low = min(a.floor_db, r.sensor_floor_db) - 15
    ax.set_ylim(max(low, float(np.percentile(a.psd_db, 1)) - 3), float(np.max(a.psd_db)) + 5)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    if title:
        ax.set_title(title, fontsize=10)
    return save_figure(fig, Path(path))
