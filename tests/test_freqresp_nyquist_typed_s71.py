"""A band's top typed as the Nyquist frequency to a few digits is the Nyquist frequency: ``--wmax 3141.592654`` on a
1 kHz record (pi x 1000 = 3141.5926536) was refused as "3141.5927 rad/s is above the Nyquist frequency 3141.5927
rad/s" (black-box finding, session 71); a top really above it is still refused."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.errors import DataError
from synth.ident.spectra import frequency_response


def _record():
    t = np.arange(20000) * 1e-3
    u = np.random.default_rng(0).standard_normal(t.size)
    return record_from_arrays(t, u, np.convolve(u, [0.5, 0.3, 0.2])[: t.size])


def test_the_nyquist_frequency_typed_to_seven_digits_is_accepted_and_above_it_is_not():
    resp = frequency_response(_record(), 10.0, 3141.592654)
    assert resp.w[-1] == pytest.approx(np.pi * 1000, rel=1e-12)
    with pytest.raises(DataError, match="above the Nyquist frequency"):
        frequency_response(_record(), 10.0, 3142.0)
