"""cvxpy, imported without paying for ``scipy.stats``.

cvxpy 1.x imports ``scipy.stats`` at import time for one function (``entropy``, used to evaluate its
quantum relative entropy atom numerically), and importing ``scipy.stats`` costs about half a second, as
much as the rest of cvxpy and more than a whole PI design. While cvxpy is imported here, ``scipy.stats``
is a stand-in module whose ``entropy`` imports the real function when first called and whose every other
attribute loads the real ``scipy.stats`` at once; afterwards the stand-in is gone from ``sys.modules``, so
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
import types
from typing import Any

__all__ = ["cp"]


def _load_cvxpy() -> Any:
    """Import cvxpy with the ``scipy.stats`` stand-in in place (the plain import when it is loaded already)."""
    if "cvxpy" in sys.modules or "scipy.stats" in sys.modules:
        return importlib.import_module("cvxpy")
    stand_in = types.ModuleType("scipy.stats", "stand-in while cvxpy is imported (synth.synthesis.cvxpy_loader)")

    def real_stats() -> Any:
        if sys.modules.get("scipy.stats") is stand_in:
            del sys.modules["scipy.stats"]
        return importlib.import_module("scipy.stats")

    def entropy(*args: Any, **kwargs: Any) -> Any:
        return real_stats().entropy(*args, **kwargs)

    def attribute(name: str) -> Any:
        if name.startswith("__"):  # the import system's own probes (``__path__``, ...): a plain module
            raise AttributeError(name)
        return getattr(real_stats(), name)

    stand_in.entropy = entropy  # type: ignore[attr-defined]
    stand_in.__getattr__ = attribute  # type: ignore[method-assign]
    sys.modules["scipy.stats"] = stand_in
    try:
        return importlib.import_module("cvxpy")
    finally:
        if sys.modules.get("scipy.stats") is stand_in:
            del sys.modules["scipy.stats"]


cp = _load_cvxpy()
