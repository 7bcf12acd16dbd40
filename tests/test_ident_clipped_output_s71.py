"""identify names an output that rests on its extreme value (session 70's "left": a step train whose output was
clipped at its top 5 % gave a confident model, exit 0, nothing said about the clip)."""

from __future__ import annotations

import numpy as np
from scipy import signal

from synth.ident.identification import identify


def _train(clip: float, seed: int = 0):
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 40.0, 1e-3)
    u = np.where((t // 2) % 2 == 0, 1.0, 0.0)
    y = signal.lsim(signal.lti([3.0], [1.0, 2.5, 1.0]), u, t)[1] + rng.normal(0.0, 0.02, t.size)
    if clip > 0:
        y = np.minimum(y, np.quantile(y, 1 - clip))
    return t, u, y


def test_a_clipped_output_is_named_in_the_records_notes_and_a_clean_one_is_not():
    clipped = identify(_train(0.05), "k/((s+p1)*(s+p2))", delay=0.0)
    notes = [n for n in clipped.record.notes if "rests on its maximum" in n]
    assert len(notes) == 1 and "clipped" in notes[0] and "reads the clipped samples" in notes[0]
    level = float(np.quantile(_train(0.05)[2], 1.0))
    assert f"{level:.4g}" in notes[0]
    assert clipped.to_dict()["record"]["notes"] == list(clipped.record.notes)
    clean = identify(_train(0.0), "k/((s+p1)*(s+p2))", delay=0.0)
    assert not any("rests on its" in n for n in clean.record.notes)
