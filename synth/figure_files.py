"""Saving figures: one PNG format for every report (matplotlib's Agg backend, 110 dpi, tagged as synth's)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

__all__ = ["DPI", "METADATA", "save_figure"]

METADATA = {"Software": "synth"}

DPI = 110
"""Resolution of every report figure (dots per inch)."""


def save_figure(fig: plt.Figure, path: str | Path, dpi: int = DPI) -> Path:
    """Lay out, write ``path`` as PNG (creating its folder) and close ``fig``.

    Examples
    --------
    >>> import tempfile
    >>> fig, ax = plt.subplots(); _ = ax.plot([0, 1], [0, 1])
    >>> save_figure(fig, Path(tempfile.mkdtemp()) / "sub" / "line.png").name
    'line.png'
    """
    path = Path(path)
    fig.set_dpi(dpi)  # lay out at the dpi written: the text extents measured here are reused by savefig
    fig.tight_layout()
    # tight_layout leaves a placeholder layout engine behind, and savefig draws a figure with any engine once
    # more before the draw it writes (all of the layout work again, without the pixels): none is needed now
    fig.set_layout_engine(None)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi, metadata=METADATA)
    plt.close(fig)
    return path
