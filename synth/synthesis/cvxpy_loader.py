"""cvxpy, imported without paying for ``scipy.stats``.

cvxpy 1.x imports ``scipy.stats`` at import time for one function (``entropy``, used to evaluate its
quantum relative entropy atom numerically), and importing ``scipy.stats`` costs about half a second, as
much as the rest of cvxpy and more than a whole PI design. While cvxpy is imported here, ``scipy.stats``
is a stand-in (:mod:`synth.stats_stand_in`) whose ``entropy`` imports the real function when first called and
whose every other attribute loads the real ``scipy.stats`` at once; afterwards the stand-in is gone from ``sys.modules``, so
any later ``import scipy.stats`` gets the real module. Nothing cvxpy computes changes: only when
``scipy.stats`` is loaded.

Examples
--------
>>> import cvxpy
>>> from synth.synthesis.cvxpy_loader import cp
>>> cp is cvxpy
True
>>> import scipy.stats, numpy as np  # the real module, whether cvxpy loaded it or not
>>> bool(np.isclose(scipy.stats.entropy([0.5, 0.5]), np.log(2)))
True
"""

from __future__ import annotations

import importlib
import sys
from typing import Any

from synth.stats_stand_in import scipy_stats_stand_in

__all__ = ["cp"]


def _load_cvxpy() -> Any:
    """Import cvxpy with the ``scipy.stats`` stand-in in place (:mod:`synth.stats_stand_in`: its ``entropy``
    loads the real function when first called)."""
    if "cvxpy" in sys.modules:
        return importlib.import_module("cvxpy")
    with scipy_stats_stand_in(lazy=("entropy",)):
        return importlib.import_module("cvxpy")


cp = _load_cvxpy()
