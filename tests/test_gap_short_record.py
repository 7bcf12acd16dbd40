"""A record too short for the default 16 Welch segments of 8 samples (a black-box test's 113-row ESC thrust-stand
log): diagnose refused it with "n_segments: need at least 2 segments of 8 samples", a parameter no user can set. The
where stage now takes fewer segments; the held-out test, which needs 10 segments of 10 samples, says what to do."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lsim

from synth.data import record_from_arrays
from synth.errors import ModelError
from synth.gap.diagnose import diagnose
from synth.plant import Plant


def _steps(n: int, seed: int):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.05
    u = np.repeat(rng.uniform(-1, 1, n // 10 + 1), 10)[:n]
    y = lsim(([2.0], [0.3, 1.0]), np.r_[np.zeros(2), u[:-2]], t, interp=False)[1]   # 0.1 s of delay
    return record_from_arrays(t, u, y + 0.01 * rng.normal(size=n))


def test_a_short_record_with_a_longer_validation_record_is_diagnosed() -> None:
    d = diagnose(Plant.from_string("2/(0.3*s+1)"), _steps(113, 0), validate=_steps(600, 1), candidates=["delay"],
                 n_null=9, n_boot=200)
    assert d.verdict["effects"] == ["delay"], d.summary
    assert 0.07 < d.attribution.effects[0].parameters["delay"] < 0.13
    assert d.localization.where.frequency.coherence.n_segments == 14   # 113 // 8


def test_a_short_record_alone_says_what_the_held_out_test_needs() -> None:
    with pytest.raises(ModelError, match=r"57 held-out samples are too few for the held-out test \(10 segments of at "
                                         r"least 10 samples: 100\); record longer, or give --validate"):
        diagnose(Plant.from_string("2/(0.3*s+1)"), _steps(113, 0), candidates=["delay"], n_null=9, n_boot=200)
