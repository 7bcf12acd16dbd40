"""Saving figures: one PNG format for every report (matplotlib's Agg backend, 110 dpi, tagged as synth's)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.ticker import LogLocator

__all__ = ["DPI", "LOG_MINOR_SUBS", "METADATA", "save_figure"]

METADATA = {"Software": "synth"}

DPI = 110
"""Resolution of every report figure (dots per inch)."""

LOG_MINOR_SUBS = (2.0, 5.0)
"""Minor ticks (and minor grid lines) of a log axis spanning two decades or more: at 2 and 5 times each power of
ten, instead of matplotlib's eight per decade. Easier to read, and each tick is an object matplotlib lays out
and draws (a Bode figure: 0.17 -> 0.13 s)."""


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
    _lighter_log_minor_ticks(fig)
    fig.set_dpi(dpi)  # lay out at the dpi written: the text extents measured here are reused by savefig
    fig.tight_layout()
    # tight_layout leaves a placeholder layout engine behind, and savefig draws a figure with any engine once
    # more before the draw it writes (all of the layout work again, without the pixels): none is needed now
    fig.set_layout_engine(None)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi, metadata=METADATA)
    plt.close(fig)
    return path


def _lighter_log_minor_ticks(fig: plt.Figure) -> None:
    """Put the minor ticks of each log axis with matplotlib's default minor locator that spans two decades or
    more (where they carry no labels) at :data:`LOG_MINOR_SUBS`."""
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            locator = axis.get_minor_locator()
            subs = getattr(locator, "_subs", None)
            if axis.get_scale() != "log" or type(locator) is not LogLocator or not (isinstance(subs, str)
                                                                                   and subs == "auto"):
                continue  # a locator a figure chose itself (an array of subs, say) is left alone
            lo, hi = sorted(axis.get_view_interval())
            if lo > 0 and hi >= 100.0 * lo:
                axis.set_minor_locator(LogLocator(subs=LOG_MINOR_SUBS))
