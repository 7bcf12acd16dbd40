"""Parts of :mod:`scipy.stats` without its import.

Importing ``scipy.stats`` runs its package ``__init__``, which builds every distribution: about 0.3 s, more than
a PI design. synth needs two small pieces of it on the design path: cvxpy's import reaches for ``entropy`` (one
function, for an atom synth never uses) and the exact search draws scrambled Sobol points (``scipy.stats.qmc``).
:func:`scipy_stats_stand_in` puts a stand-in package in ``sys.modules`` for the length of a ``with`` block: its
submodules (``scipy.stats.qmc``) load from the real package's folder without the package's ``__init__``, the
names given as ``lazy`` are functions that call the real ones, and any other attribute loads the real package
at once. Afterwards the stand-in is gone from ``sys.modules``, so a later ``import scipy.stats`` gets the real
package (which reuses the submodules already loaded). Nothing computed changes: only when ``scipy.stats`` loads.

Examples
--------
>>> points = sobol_points(2, 4, seed=0)
>>> points.shape, bool(((points >= 0) & (points < 1)).all())
((4, 2), True)
>>> import scipy.stats, numpy as np  # the real package, whether the stand-in was used first or not
>>> bool(np.isclose(scipy.stats.norm.cdf(0.0), 0.5))
True
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import types
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

__all__ = ["scipy_stats_stand_in", "sobol_points"]


@contextmanager
def scipy_stats_stand_in(lazy: tuple[str, ...] = ()) -> Iterator[None]:
    """Within the block, ``scipy.stats`` is a stand-in package (nothing changes when the real one is loaded).

    Parameters
    ----------
    lazy : tuple of str
        Functions of ``scipy.stats`` that ``from scipy.stats import name`` may take without loading it: each
        is a function that loads the real package when first called and calls its namesake.

    Examples
    --------
    >>> import sys
    >>> with scipy_stats_stand_in(lazy=("entropy",)):
    ...     from scipy.stats import entropy
    >>> round(float(entropy([0.5, 0.5])), 6)  # the real function, called through the stand-in's
    0.693147
    """
    if "scipy.stats" in sys.modules:
        yield
        return
    found = importlib.util.find_spec("scipy.stats")
    stand_in = types.ModuleType("scipy.stats", "stand-in while parts of it load (synth.stats_stand_in)")
    stand_in.__path__ = list(found.submodule_search_locations or [])  # submodules load from the real folder
    stand_in.__spec__ = found  # and its data files (qmc's Sobol direction numbers) are found there

    def real() -> Any:
        if sys.modules.get("scipy.stats") is stand_in:
            del sys.modules["scipy.stats"]
        return importlib.import_module("scipy.stats")

    def calling(name: str) -> Any:
        return lambda *args, **kwargs: getattr(real(), name)(*args, **kwargs)

    def attribute(name: str) -> Any:
        if name.startswith("__"):  # the import system's own probes: a plain module
            raise AttributeError(name)
        return getattr(real(), name)

    for name in lazy:
        setattr(stand_in, name, calling(name))
    stand_in.__getattr__ = attribute  # type: ignore[method-assign]
    sys.modules["scipy.stats"] = stand_in
    try:
        yield
    finally:
        if sys.modules.get("scipy.stats") is stand_in:
            del sys.modules["scipy.stats"]


def sobol_points(dimension: int, size: int, seed: int) -> np.ndarray:
    """``size`` points of a scrambled Sobol sequence in ``[0, 1)^dimension`` (``scipy.stats.qmc.Sobol`` with
    ``scramble=True`` and ``seed``), its module loaded without the rest of ``scipy.stats``.

    Examples
    --------
    >>> import scipy.stats
    >>> bool((sobol_points(3, 8, seed=5) == scipy.stats.qmc.Sobol(3, scramble=True, seed=5).random(8)).all())
    True
    """
    with scipy_stats_stand_in():  # the first engine of a process also reads its direction numbers
        engine = importlib.import_module("scipy.stats.qmc").Sobol(dimension, scramble=True, seed=seed)
    return engine.random(size)
