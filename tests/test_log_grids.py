"""``log_grids`` builds every row at once; each row must be bit for bit the row ``log_grid`` gives alone (the batch
requirement evaluations and the one-loop evaluations then see the same frequencies)."""

import numpy as np
import pytest

from synth.freqgrid import log_grid, log_grids


@pytest.mark.parametrize("per_decade", [1, 5, 40, 160])
def test_every_row_is_log_grid_exactly(per_decade):
    rng = np.random.default_rng(per_decade)
    lo = 10.0 ** rng.uniform(-4, 3, 60)
    hi = lo * 10.0 ** rng.uniform(0.0, 6.0, 60)
    lo[:3], hi[:3] = [1.0, 2.0, 2.0], [1.0, 2.0, 2.0 + 1e-12]  # equal and nearly equal ends
    lo, hi = np.concatenate([lo, lo[:5]]), np.concatenate([hi, hi[:5]])  # repeated rows
    grids = log_grids(lo, hi, per_decade)
    assert grids.shape[0] == lo.size
    for row, a, b in zip(grids, lo, hi):
        alone = log_grid(a, b, per_decade)
        assert np.array_equal(row[: alone.size], alone)
        assert np.all(row[alone.size:] == b)
