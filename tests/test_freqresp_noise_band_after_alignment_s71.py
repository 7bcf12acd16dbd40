"""A noise input behind a delay: realigned, the band is not cut back to the estimate's before the move.

Black-box finding (session 71): white noise through ``95/(s+95)`` behind 0.1 s, no output noise, 30 s at 1 kHz. The
windows (down to 1.5 s) see the delay as a loss of coherence at the top, so the estimate before the move ended at
252 rad/s; after the move every point up to 628 rad/s had coherence 0.999 and lay within 0.05 dB of the truth, yet
the band was cut back to 252 rad/s (while a note said the response stays coherent up to 2513 rad/s). Past the
first band the realigned band is now kept where the input excites as strongly (a sweep's end still cuts it:
tests/test_freqresp_alignment.py)."""

from __future__ import annotations

import numpy as np
from scipy import signal

from synth.data import record_from_arrays
from synth.ident.spectra import frequency_response


def _record(seed: int, delay_samples: int):
    dt = 1e-3
    t = np.arange(30000) * dt
    u = np.random.default_rng(seed).standard_normal(t.size)
    b, a, _ = signal.cont2discrete(([95.0], [1.0, 95.0]), dt, method="zoh")
    b = np.squeeze(b)
    y = signal.lfilter(b, a, np.r_[np.zeros(delay_samples), u[:-delay_samples]])
    return record_from_arrays(t, u, y), (b, a, dt, delay_samples)


def test_a_noise_input_behind_a_delay_keeps_its_whole_coherent_band():
    for seed in (1, 2):
        record, (b, a, dt, k) = _record(seed, 100)
        resp = frequency_response(record)
        assert any("output was moved" in n for n in resp.notes)
        assert resp.band.w_max >= 0.99 * resp.w[-1]  # was 252 rad/s of 628
        inside = resp.band.contains(resp.w)
        z = np.exp(1j * resp.w[inside] * dt)
        truth = np.polyval(b, z) / np.polyval(a, z) * z ** (-k)
        ratio = resp.H[inside] / truth
        assert np.max(np.abs(20 * np.log10(np.abs(ratio)))) < 0.2
        assert np.max(np.abs(np.degrees(np.angle(ratio)))) < 2.0
