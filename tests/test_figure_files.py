"""save_figure's lighter minor ticks on log axes: matplotlib's default minor locator over two decades or more
gets ticks at 2 and 5 per decade; a locator a figure set itself, and a short log axis, are left alone."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import LogLocator

from synth.figure_files import LOG_MINOR_SUBS, save_figure


def _minor_subs(tmp_path, setup) -> object:
    fig, ax = plt.subplots()
    setup(ax)
    kept = {}
    original = fig.savefig

    def spy(*args, **kwargs):  # read the locator as it is when the file is written
        kept["subs"] = ax.xaxis.get_minor_locator()._subs
        return original(*args, **kwargs)

    fig.savefig = spy
    save_figure(fig, tmp_path / "f.png")
    assert (tmp_path / "f.png").stat().st_size > 1000
    return kept["subs"]


def test_a_wide_log_axis_gets_minor_ticks_at_2_and_5(tmp_path):
    subs = _minor_subs(tmp_path, lambda ax: ax.semilogx([0.01, 1000.0], [0.0, 1.0]))
    assert tuple(np.asarray(subs, float)) == LOG_MINOR_SUBS


def test_a_short_log_axis_and_a_chosen_locator_are_left_alone(tmp_path):
    assert _minor_subs(tmp_path, lambda ax: ax.semilogx([1.0, 30.0], [0.0, 1.0])) == "auto"

    def chosen(ax):
        ax.semilogx([0.01, 1000.0], [0.0, 1.0])
        ax.xaxis.set_minor_locator(LogLocator(subs=(1.5, 3.0, 7.0)))

    assert tuple(np.asarray(_minor_subs(tmp_path, chosen), float)) == (1.5, 3.0, 7.0)


def test_log_tick_labels_are_plain_unicode_and_mathtext_is_not_parsed(tmp_path, monkeypatch):
    import matplotlib.mathtext

    parsed = []
    original_parse = matplotlib.mathtext.MathTextParser.parse
    monkeypatch.setattr(matplotlib.mathtext.MathTextParser, "parse",
                        lambda self, s, *a, **k: parsed.append(s) or original_parse(self, s, *a, **k))
    fig, ax = plt.subplots()
    ax.loglog([0.001, 100.0], [0.5, 3.0])  # y spans less than a decade: its minor ticks get labels (2x10^0 ...)
    labels = {}
    original = fig.savefig

    def spy(*args, **kwargs):
        result = original(*args, **kwargs)
        labels["x"] = [t.get_text() for t in ax.get_xticklabels()]
        labels["y"] = [t.get_text() for t in ax.yaxis.get_minorticklabels() if t.get_text()]
        return result

    fig.savefig = spy
    save_figure(fig, tmp_path / "f.png")
    assert "10\u207b\u00b3" in labels["x"] and "10\u00b2" in labels["x"] and "10\u2070" in labels["x"]
    assert "2\u00d710\u2070" in labels["y"] and "6\u00d710\u207b\u00b9" in labels["y"]
    assert not any("$" in t for t in labels["x"] + labels["y"])
    assert parsed == []
