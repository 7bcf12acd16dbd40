"""The band's top against a sweep that stops at full amplitude: its ends are tested on the whole runs' transforms too.

Black-box finding (session 71): a log sweep 0.1055-4.374 rad/s over 200 s at 200 Hz, cut at full amplitude at the
record's end, into ``1.4673/(s^2 + 1.8666 s + 1.7777)`` behind 0.05 s, 1 % output noise. The band ran to 4.853 rad/s,
two grid points past the sweep's end, where the estimate was +3.4 dB and +12 deg off at coherence 0.98: the input
autospectrum the band's ends were tested on was the composite's there (the 100 s window's cells held fewer than
eight bins), whose main lobe spreads the sweep's power past its end."""

from __future__ import annotations

import numpy as np
from scipy import signal

from synth.data import record_from_arrays
from synth.ident.excitation_edge import excitation_level
from synth.ident.spectra import frequency_response

END = 2 * np.pi * 0.69611212  # rad/s


def _record():
    fs = 200.0
    t = np.arange(40000) / fs
    f0, k = 0.016798411, (0.69611212 / 0.016798411) ** (1 / t[-1])
    u = np.sin(2 * np.pi * f0 * (k**t - 1) / np.log(k))
    b, a, _ = signal.cont2discrete(([1.4672852505628045], [1.0, 1.8666235290598931, 1.7776956118571479]), 1 / fs,
                                   method="zoh")
    y = signal.lfilter(np.squeeze(b), a, np.r_[np.zeros(10), u[:-10]])
    y = y + 0.01 * np.std(y) * np.random.default_rng(0).standard_normal(y.size)
    return record_from_arrays(t, u, y)


def test_the_band_stops_within_a_grid_cell_of_the_sweeps_end():
    resp = frequency_response(_record())
    cell = 10 ** (1 / 40)  # the default 40 points per decade
    assert END / cell < resp.band.w_max <= END * cell  # was 4.853 rad/s, END * cell**2


def test_the_whole_runs_level_only_lowers_the_composites_where_cells_hold_enough_bins():
    record = _record()
    grid = np.geomspace(0.5, 8.0, 49)
    composite = np.ones(grid.size)

    class Window:  # a window too short to resolve anything here (fewer than eight bins in every cell)
        length, gxx = 1.0, np.ones(grid.size)

    without = excitation_level([Window()], grid, composite)
    with_runs = excitation_level([Window()], grid, composite, [record])
    assert np.array_equal(without, composite) and np.all(with_runs <= composite)
    past = grid > 1.2 * END
    assert np.all(with_runs[past] < 1e-3) and np.all(with_runs[grid < 0.8 * END] == 1.0)
