"""Figures of a frequency-sweep identification (matplotlib, Agg backend, PNG).

Each function takes results and a path and returns the path; nothing here
computes anything the results do not hold.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from synth.figure_files import save_figure
from synth.ident.freqfit import FreqFit
from synth.ident.spectra import FrequencyResponse
from synth.ident.step_verification import StepVerification

__all__ = ["bode_figure", "verification_figure"]


def bode_figure(resp: FrequencyResponse, path: str | Path, fit: FreqFit | None = None) -> Path:
    """Magnitude, phase and coherence of the estimate (coherent band shaded), with the fit if given.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from synth.ident.coherence import coherent_band
    >>> w = np.geomspace(1, 10, 5); b = coherent_band(w, np.ones(5))
    >>> r = FrequencyResponse(w, 1 / (1j * w + 1), np.ones(5), np.full(5, .05), np.ones(5), np.ones(5),
    ...                       np.ones(5), np.ones(5, complex), b, (10.0,))
    >>> bode_figure(r, pathlib.Path(tempfile.mkdtemp()) / "bode.png").exists()
    True
    """
    fig, (ax_m, ax_p, ax_c) = plt.subplots(3, 1, figsize=(7.5, 8.5), sharex=True,
                                           gridspec_kw={"height_ratios": [3, 3, 1.6]})
    mag, ph = resp.magnitude_db, resp.phase_deg
    err_db = 20 * np.log10(1 + np.nan_to_num(resp.random_error, nan=0.0, posinf=0.0))
    ax_m.semilogx(resp.w, mag, color="#1f4e9c", label=f"estimate ({resp.kind})")
    ax_m.fill_between(resp.w, mag - err_db, mag + err_db, color="#1f4e9c", alpha=0.15, lw=0,
                      label="random error (1 sigma)")
    ax_p.semilogx(resp.w, ph, color="#1f4e9c")
    if fit is not None:
        w = fit.w
        Hm = fit.H_model
        k = np.argmin(np.abs(resp.w - w[0]))
        phm = np.degrees(np.unwrap(np.angle(Hm)))
        phm += 360.0 * np.round((ph[k] - phm[0]) / 360.0)
        ax_m.semilogx(w, 20 * np.log10(np.abs(Hm)), "--", color="#c0392b", label=f"fit {fit.structure}, J = {fit.J:.3g}")
        ax_p.semilogx(w, phm, "--", color="#c0392b")
    ax_c.semilogx(resp.w, resp.coherence, color="#2e8b57")
    ax_c.axhline(resp.band.threshold, color="0.5", lw=0.8, ls=":")
    for ax in (ax_m, ax_p, ax_c):
        if resp.band.found:
            ax.axvspan(resp.band.w_min, resp.band.w_max, color="#2e8b57", alpha=0.08, lw=0)
        ax.grid(True, which="both", alpha=0.3)
    ax_m.set_ylabel("magnitude [dB]")
    ax_p.set_ylabel("phase [deg]")
    ax_c.set_ylabel("coherence")
    ax_c.set_ylim(0, 1.05)
    ax_c.set_xlabel("frequency [rad/s]  (shaded: coherent band)")
    ax_m.set_title(f"{resp.output} / {resp.input}")
    ax_m.legend(loc="best", fontsize=8)
    return save_figure(fig, Path(path))


def verification_figure(v: StepVerification, path: str | Path, label: str = "model") -> Path:
    """Measured step response and the fitted model's simulation, input below.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> t = np.linspace(0, 1, 11)
    >>> v = StepVerification(90.0, 0.1, 0.01, t, t > 0.5, t, t * 0.9)
    >>> verification_figure(v, pathlib.Path(tempfile.mkdtemp()) / "step.png").exists()
    True
    """
    fig, (ax_y, ax_u) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
    ax_y.plot(v.t, v.y, color="0.3", lw=1, label="measured")
    ax_y.plot(v.t, v.y_model, color="#c0392b", lw=1.4, label=f"{label} (fit {v.fit_percent:.1f} %)")
    ax_u.plot(v.t, v.u, color="#1f4e9c", lw=1)
    ax_y.set_ylabel("output")
    ax_u.set_ylabel("input")
    ax_u.set_xlabel("time [s]")
    ax_y.set_title(f"time-domain verification: {Path(v.source).name or 'step record'}")
    ax_y.legend(loc="best", fontsize=8)
    for ax in (ax_y, ax_u):
        ax.grid(True, alpha=0.3)
    return save_figure(fig, Path(path))
