"""The formula fit's start matched to the orders fit (synth.ident.freqfit_start.matched_start) reaches the
coefficients' own signs: from positive starts alone a match of ``c*(s+z)`` to ``c < 0, z < 0`` must cross
``c = 0, z -> inf`` and stopped there on 4 of these 40 targets (c = 0, z = 1.7e5 to 1.8e7); in a test worker of the CI
it stopped there for the right-half-plane zero of ``tests/test_freqfit_nmp_start_s71.py`` too, whose fit then failed.
The starts are now tried with their sign patterns, the closest first."""

from __future__ import annotations

import numpy as np

from synth.ident.freqfit_start import matched_start
from synth.ident.structure import parse_structure


def test_every_target_with_negative_gain_and_zero_is_matched_exactly():
    st = parse_structure("c*(s+z)/((s+p1)*(s+p2))")
    rng = np.random.default_rng(0)
    missed = []
    for i in range(40):
        c, z = -10 ** rng.uniform(-1, 2), -10 ** rng.uniform(-1, 2)
        p1, p2 = 10 ** rng.uniform(-1, 2, 2)
        theta = matched_start(st, np.array([c, c * z]), np.poly([-p1, -p2]),
                              [np.full(4, v) for v in (1.0, 0.5, 3.0, 20.0)])
        # the signs' barrier is in c and z: they must be matched (the poles of case 29, 33.4 and 0.159 beside a zero
        # at 0.158, came out as a double pole at 2.37 in a CI test worker, exact in a plain process)
        if not (abs(theta[0] - c) < 1e-4 * abs(c) and abs(theta[1] - z) < 1e-4 * abs(z)):
            missed.append((i, c, z, theta))
    assert not missed, missed
