"""Slow output drift: a straight line (or a parabola) in time added to the model's output.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``drift``              output    ``y + d1 (t - t0) + d2 (t - t0)^2``                          ``slope, curvature``
=====================  ========  ===========================================================  ==============
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import Effect, Params

__all__ = ["DriftEffect"]


@dataclass(frozen=True)
class DriftEffect(Effect):
    """Slow output drift: ``slope (t - t0)``, and ``+ curvature (t - t0)^2`` for ``order="quadratic"``.

    ``t0`` is the record's start. The default is the straight line: a curvature fitted on
    the training part of a record and carried over the held-out part grows quadratically
    beyond the data it was fitted on, so it is asked for explicitly
    (``make_effect("drift(quadratic)")``).

    Examples
    --------
    >>> import numpy as np
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 3, 1.0)
    >>> DriftEffect().apply(Plant.from_string("1"), t, np.zeros(3), {"slope": 0.5}).tolist()
    [0.0, 0.5, 1.0]
    >>> DriftEffect("quadratic").basis_names, DriftEffect("quadratic").label
    (('slope', 'curvature'), 'drift(quadratic)')
    """

    order: str = "linear"
    t0: float = 0.0
    name: ClassVar[str] = "drift"
    side: ClassVar[str] = "output"
    spellings: ClassVar[dict[str, dict[str, str]]] = {"drift(quadratic)": {"order": "quadratic"}}
    default_candidates: ClassVar[tuple[str, ...]] = ("drift",)

    def __post_init__(self) -> None:
        if self.order not in ("linear", "quadratic"):
            raise ModelError(f"drift order must be 'linear' or 'quadratic', got {self.order!r}", where="candidates")

    @property
    def parameter_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return ("slope", "curvature") if self.order == "quadratic" else ("slope",)

    @property
    def basis_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return self.parameter_names

    @property
    def label(self) -> str:
        return "drift" if self.order == "linear" else "drift(quadratic)"

    def off(self) -> Params:
        return {name: 0.0 for name in self.parameter_names}

    def output_basis(self, t: np.ndarray) -> list[np.ndarray]:
        tau = np.asarray(t, float) - self.t0
        return [tau, tau**2][: len(self.parameter_names)]
