"""Whether a fitted candidate is still the effect it names: the sign of its basis parameters, and what the effect itself
checks.

A basis parameter (:mod:`synth.gap.effects.base`) is solved by unconstrained least squares and can come out with
a sign no such effect has: a noise-free record half a sample ahead of a first-order model was "explained by
supply sag, sag = -0.498", a supply that rises when the command steps up. Only the sign is checked, against a
one-signed range in :meth:`~synth.gap.effects.base.Effect.bounds`; the magnitudes there are search ranges, not
physics (a benchmark's strong cubic spring lies beyond them), and the grid and factor parameters are searched
inside their ranges anyway. An effect may also say when a fit is not what its name says
(:meth:`synth.gap.effects.dynamics.ResonanceEffect.unlike_its_name`: a mode without a peak).
"""

from __future__ import annotations

import numpy as np

from synth.gap.effects.base import Effect, Params
from synth.plant import Plant

__all__ = ["BOUND_SLACK", "wrong_sign"]

#: how far past zero a basis parameter with a one-signed physical range may lie, as a share of that range: a fit a
#: little past zero is still that effect (switched almost off)
BOUND_SLACK = 0.05


def wrong_sign(effect: Effect, params: Params, t: np.ndarray, u: np.ndarray, plant: Plant) -> str:
    """Why a basis parameter of ``params`` has a sign the effect's physical range excludes ('' when none has).

    Examples
    --------
    >>> from synth.gap.effects.supply import SupplySagEffect
    >>> t = np.arange(0, 1, 0.01); u = np.where(t > 0.5, 1.0, 0.0); G = Plant.from_string("1/(s+1)")
    >>> wrong_sign(SupplySagEffect(), {"sag": -0.5, "tau": 0.1}, t, u, G)
    'sag = -0.5 has the wrong sign: its physical range is [0, 1] for this record'
    >>> wrong_sign(SupplySagEffect(), {"sag": 3.0, "tau": 0.1}, t, u, G)     # strong, not unphysical
    ''
    """
    for name, (lo, hi) in effect.bounds(t, u, plant).items():
        if name not in params or name not in effect.basis_names:
            continue
        x = float(params[name])
        if not np.isfinite(x):
            continue
        slack = BOUND_SLACK * (hi - lo) if np.isfinite(hi - lo) else 0.0
        if (lo >= 0.0 and x < lo - slack) or (hi <= 0.0 and x > hi + slack):
            return f"{name} = {x:.4g} has the wrong sign: its physical range is [{lo:.4g}, {hi:.4g}] for this record"
    unlike = getattr(effect, "unlike_its_name", None)  # an effect that knows when a fit is not what it names
    return unlike(params) if unlike is not None else ""
