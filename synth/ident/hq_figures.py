"""Figure of the handling-qualities metrics: Bode plot with the constructions of seed 2, fig. 1.

Draws only what :class:`synth.ident.hq_metrics.HQMetrics` holds: its curve, ``w180`` and ``2 w180``, the
-135 deg and -180 deg lines, the gain 6 dB above the gain at ``w180``, both bandwidths and the
phase-delay chord (or the least-squares phase line) from ``w180`` to ``2 w180``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from synth.errors import ModelError
from synth.figure_files import save_figure
from synth.ident.hq_metrics import GAIN_MARGIN_DB, HQMetrics

__all__ = ["hq_bode"]


def hq_bode(m: HQMetrics, path: str | Path, title: str = "") -> Path:
    """Bode plot (gain, phase and coherence when measured) with w180, 2 w180, both bandwidths and tau_p.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from synth.plant import Plant
    >>> from synth.ident.hq import hq_from_plant
    >>> m = hq_from_plant(Plant.from_string("1/(s^2+s+1)", delay=0.1))
    >>> hq_bode(m, pathlib.Path(tempfile.mkdtemp()) / "hq.png").suffix
    '.png'
    """
    if m.w is None or m.magnitude_db is None or m.phase_deg is None:
        raise ModelError("the metrics carry no frequency response to draw")
    path = Path(path)
    marks = [v for v in (m.bandwidth_phase, m.bandwidth_gain, m.w180) if v]
    lo = max(float(m.w[0]), min(marks) / 10) if marks else float(m.w[0])
    hi = min(float(m.w[-1]), 4 * m.w180) if m.w180 else float(m.w[-1])
    if m.source == "measured" and m.w180:
        hi = float(m.w[-1])
    keep = (m.w >= lo) & (m.w <= hi)
    w, mag, ph = m.w[keep], m.magnitude_db[keep], m.phase_deg[keep]
    rows = 3 if m.coherence is not None else 2
    fig, axes = plt.subplots(rows, 1, figsize=(8, 7.5 if rows == 3 else 6.2), sharex=True,
                             gridspec_kw={"height_ratios": [3, 3, 1.3][:rows]})
    ax_m, ax_p = axes[0], axes[1]
    style = "o-" if m.source == "measured" else "-"
    ax_m.semilogx(w, mag, style, color="#1f4e9c", ms=2.5, lw=1.4)
    ax_p.semilogx(w, ph, style, color="#1f4e9c", ms=2.5, lw=1.4)
    ax_p.axhline(-135, color="#2e8b57", ls="--", lw=1)
    ax_p.axhline(-180, color="#c0392b", ls="--", lw=1)
    ax_p.text(w[0], -135, " -135 deg (45 deg margin)", color="#2e8b57", va="bottom", fontsize=8)
    ax_p.text(w[0], -180, " -180 deg", color="#c0392b", va="top", fontsize=8)
    if m.bandwidth_phase:
        for ax in (ax_m, ax_p):
            ax.axvline(m.bandwidth_phase, color="#2e8b57", lw=1)
        ax_p.plot([m.bandwidth_phase], [-135], "o", color="#2e8b57")
        ax_m.text(m.bandwidth_phase, 0.02, f" w_BW,phase {m.bandwidth_phase:.3g}", transform=ax_m.get_xaxis_transform(),
                  color="#2e8b57", fontsize=8, rotation=90, va="bottom")
    if m.w180 and m.gain_w180_db is not None:
        for ax in (ax_m, ax_p):
            ax.axvline(m.w180, color="#c0392b", lw=1)
            if 2 * m.w180 <= hi:
                ax.axvline(2 * m.w180, color="#c0392b", lw=1, ls=":")
        ax_m.axhline(m.gain_w180_db, color="#c0392b", ls=":", lw=1)
        level = m.gain_w180_db + GAIN_MARGIN_DB
        ax_m.axhline(level, color="#d35400", ls="--", lw=1)
        ax_m.text(w[-1], level, f"gain at w180 + 6 dB ({level:.1f} dB) ", color="#d35400", fontsize=8,
                  ha="right", va="bottom")
        ax_m.text(m.w180, 0.02, f" w180 {m.w180:.4g}", transform=ax_m.get_xaxis_transform(), color="#c0392b",
                  fontsize=8, rotation=90, va="bottom")
        if m.bandwidth_gain:
            ax_m.axvline(m.bandwidth_gain, color="#d35400", lw=1)
            ax_m.plot([m.bandwidth_gain], [level], "o", color="#d35400")
            ax_m.text(m.bandwidth_gain, 0.02, f" w_BW,gain {m.bandwidth_gain:.3g}",
                      transform=ax_m.get_xaxis_transform(), color="#d35400", fontsize=8, rotation=90, va="bottom")
        if m.phase_2w180 is not None:
            if m.phase_line is not None:
                xs = np.linspace(m.phase_line.band[0], 2 * m.w180, 50)
                ax_p.plot(xs, m.phase_line.value(xs), color="#8e44ad", lw=2, label="least-squares phase line")
            else:
                ax_p.plot([m.w180, 2 * m.w180], [-180, m.phase_2w180], color="#8e44ad", lw=2,
                          label="phase-delay chord")
            ax_p.plot([2 * m.w180], [m.phase_2w180], "s", color="#8e44ad")
            label = f"tau_p = {m.phase_delay:.4f} s" if m.phase_delay is not None else ""
            ax_p.legend(loc="lower left", fontsize=8, title=label, title_fontsize=9)
    ax_m.set_ylabel("gain [dB]")
    ax_p.set_ylabel("phase [deg]")
    ph_lo = max(float(np.min(ph)), -540.0)
    ax_p.set_ylim(min(ph_lo, -200) - 10, max(float(np.max(ph)), -90) + 15)
    if rows == 3 and m.coherence is not None:
        ax_c = axes[2]
        ax_c.semilogx(w, m.coherence[keep], "o-", color="#7f8c8d", ms=2.5, lw=1)
        ax_c.axhline(0.8, color="#7f8c8d", ls="--", lw=1)
        ax_c.set_ylim(0, 1.05)
        ax_c.set_ylabel("coherence")
    axes[-1].set_xlabel("frequency [rad/s]")
    bw = f"bandwidth {m.bandwidth:.3g} rad/s ({m.bandwidth_limit}-limited, {m.response_type} response type)" \
        if m.bandwidth else "bandwidth undefined"
    fig.suptitle((title + "\n" if title else "") + bw, fontsize=10)
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
    return save_figure(fig, path)
