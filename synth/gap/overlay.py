"""Before/after overlay: the measured output, the nominal model, the re-fit alone and the re-fit with the effect.

Top: the held-out part of the record (shaded) with the four curves. Bottom:
the residuals of the nominal model, of the re-fit alone and of the accepted
effect, with the noise floor's +-2 sigma band. The title is the verdict's
headline.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from synth.gap.attribution.verdict import EffectDiagnosis

__all__ = ["overlay_figure"]


def overlay_figure(dg: EffectDiagnosis) -> plt.Figure:
    """Draw the before/after overlay of a :class:`~synth.gap.attribution.verdict.EffectDiagnosis`.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 8, 0.02); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(0.2*s+1)", delay=0.06), t, u)
    >>> dg = diagnose_effects(Plant.from_string("2/(0.2*s+1)"), record_from_arrays(t, u, y + 0.01 * np.sin(40 * t)),
    ...                       options=DiagnoseOptions(candidates=("delay",), n_null=3))
    >>> fig = overlay_figure(dg)
    >>> len(fig.axes), dg.verdict["effects"]
    (2, ['delay'])
    >>> plt.close(fig)
    """
    t, y, held = dg.t, dg.y, dg.heldout
    joined = dg.split.get("validation_runs", 1) > 1

    def shown(a: np.ndarray) -> np.ndarray:  # several runs: the settling bridges between them left blank
        return np.where(held, a, np.nan) if joined else a

    y = shown(y)
    fig, (ax_y, ax_e) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    t_held = t[held]
    for ax in (ax_y, ax_e):
        ax.axvspan(float(t_held[0]), float(t_held[-1]), color="0.93", zorder=0)
    ax_y.plot(t, y, color="0.2", lw=1.0, label="measured")
    ax_y.plot(t, shown(dg.y_nominal), color="tab:red", lw=1.0, label="nominal")
    ax_y.plot(t, shown(dg.y_refit), color="tab:orange", lw=1.0, ls="--", label="re-fit alone")
    ax_e.plot(t, y - dg.y_nominal, color="tab:red", lw=0.8, label="nominal")
    ax_e.plot(t, y - dg.y_refit, color="tab:orange", lw=0.8, label="re-fit alone")
    if dg.y_best is not None:
        name = dg.verdict["effects"][0]
        ax_y.plot(t, shown(dg.y_best), color="tab:blue", lw=1.0, label=f"re-fit + {name}")
        ax_e.plot(t, y - dg.y_best, color="tab:blue", lw=0.8, label=f"re-fit + {name}")
    band = 2.0 * float(np.sqrt(dg.noise_floor))
    ax_e.axhspan(-band, band, color="tab:green", alpha=0.15, label="noise +-2 sigma")
    ax_y.set_ylabel("output")
    ax_e.set_ylabel("residual")
    ax_e.set_xlabel("time [s] on the joined runs (blank: settling bridges)" if joined
                    else "time [s] (shaded: held out)")
    ax_y.legend(loc="best", fontsize=8)
    ax_e.legend(loc="best", fontsize=8)
    ax_y.set_title(dg.verdict["headline"], fontsize=9)
    fig.tight_layout()
    return fig
