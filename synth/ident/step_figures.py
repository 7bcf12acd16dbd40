"""Figures of a step-train identification (matplotlib, Agg backend, PNG tagged ``Software=synth``).

Each function takes results and a path and returns the path; nothing is
computed here that the results do not hold.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np  # noqa: F401  (doctest namespace)

from synth.data.record import Record
from synth.figure_files import save_figure
from synth.ident.timefit import TimeFitResult

__all__ = ["fit_figure", "train_figure"]


def _label(name: str, unit: str) -> str:
    return f"{name} [{unit}]" if unit else name


def fit_figure(fit: TimeFitResult, path: str | Path, title: str = "") -> Path:
    """The fitted data with the model output (top) and the residuals (bottom).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.ident.timefit import fit_structure
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 3, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(s+3)"), t, u) + 0.01 * np.sin(40 * t)
    >>> fit = fit_structure(record_from_arrays(t, u, y), "k/(s+p)")
    >>> fit_figure(fit, pathlib.Path(tempfile.mkdtemp()) / "fit.png").suffix
    '.png'
    """
    out = fit.plant.output
    fig, (ax, ax_r) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, gridspec_kw={"height_ratios": [3, 1.6]})
    ax.plot(fit.t, fit.y, color="#7f8c8d", lw=0.8, label="data")
    ax.plot(fit.t, fit.yhat, color="#c0392b", lw=1.4, label=f"fit ({fit.fit_percent:.2f} %)")
    ax.set_ylabel(_label(out.name, out.unit))
    ax.grid(alpha=0.3)
    ax.legend(loc="best")
    ax.set_title(title or f"{fit.structure.formula}, delay {fit.delay * 1000:.2f} ms")
    ax_r.plot(fit.t, fit.residuals, color="#1f4e9c", lw=0.6)
    band = 1.96 * fit.residual_std
    ax_r.axhline(band, color="k", ls="--", lw=0.7)
    ax_r.axhline(-band, color="k", ls="--", lw=0.7, label="+-1.96 residual std")
    ax_r.set_ylabel(_label("residual", out.unit))
    ax_r.set_xlabel("time [s]")
    ax_r.grid(alpha=0.3)
    ax_r.legend(loc="upper right", fontsize=8)
    return save_figure(fig, Path(path))


def train_figure(record: Record, path: str | Path, max_points: int = 20000) -> Path:
    """Overview of the raw record: input (top) and output (bottom), decimated for drawing only.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from synth.ident.x4_record import x4_step_train
    >>> train_figure(x4_step_train(periods=2), pathlib.Path(tempfile.mkdtemp()) / "train.png").suffix
    '.png'
    """
    stride = max(1, record.n // max_points)
    fig, (ax_u, ax_y) = plt.subplots(2, 1, figsize=(9, 5), sharex=True, gridspec_kw={"height_ratios": [1, 2]})
    ax_u.plot(record.t[::stride], record.u[::stride], color="#2e8b57", lw=0.8)
    ax_u.set_ylabel(_label(record.input.name, record.input.unit))
    ax_u.grid(alpha=0.3)
    ax_y.plot(record.t[::stride], record.y[::stride], color="#1f4e9c", lw=0.5)
    ax_y.set_ylabel(_label(record.output.name, record.output.unit))
    ax_y.set_xlabel("time [s]")
    ax_y.grid(alpha=0.3)
    note = f" (every {stride}th sample drawn)" if stride > 1 else ""
    ax_u.set_title(f"{record.source}{note}", fontsize=9)
    return save_figure(fig, Path(path))
