"""Which fitted parameters the record cannot pin down (weak identifiability), from the fit's covariance.

A parameter is *weakly identifiable* when its standard error is a large share of its value
(``std > WEAK_RELATIVE_STD |value|``: the 95 % interval spans about +-50 % or more), or when
it is tied to another parameter (``|correlation| >= TIED_CORRELATION``) and still known only to
``TIED_RELATIVE_STD`` or worse. The typical case is a near pole-zero cancellation: the zero
and the pole it nearly cancels move together along a ridge of the cost, each with a large
standard error and a correlation near 1. Such a number is reported with its interval and its
correlation partner, not as a confident value. The delay is measured against
``max(|delay|, dt)`` (a delay of a fraction of a sample known to a fraction of a sample is
pinned down); the output offset is a nuisance parameter and not judged.

This rests on the linearized (Gauss-Newton) covariance: where it says a parameter is weak,
its interval is also only a rough guide (the cost is far from quadratic along the ridge).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["COINCIDE", "TIED_CORRELATION", "TIED_RELATIVE_STD", "TIED_TO_WEAK", "WEAK_RELATIVE_STD", "TiedParameter",
           "WeakParameter", "coinciding", "tied_to_weak", "weak_parameters"]

#: a parameter whose standard error exceeds this share of its value is weakly identifiable
WEAK_RELATIVE_STD = 0.25
#: a correlation this close to +-1 with another parameter ties the two together ...
TIED_CORRELATION = 0.995
#: ... and makes the parameter weakly identifiable when its standard error is above this share of its value
TIED_RELATIVE_STD = 0.05
#: a pinned-down parameter correlated at least this much with a weak one has an interval no better founded
TIED_TO_WEAK = 0.9
#: parameters whose values agree to this share of their size have met (:func:`coinciding`)
COINCIDE = 1e-4

_MET = ("the model cannot tell them apart there: two roots that coincide (the record may call for a complex "
        "pair, which a quadratic factor such as (s^2+a*s+b) can fit) or a pole that cancels a zero (a lower "
        "order fits)")


def _meet(a: float, b: float, share: float = COINCIDE) -> bool:
    """Whether ``a`` and ``b`` agree to ``share`` of ``a``'s size."""
    return abs(a - b) <= share * max(abs(a), 1e-12)


def coinciding(values: dict[str, float]) -> str:
    """A sentence naming the groups of parameters whose values agree to :data:`COINCIDE` of their size and
    what that says about the structure (empty when none do): a fit that ends or stalls there sits where two of
    its roots meet. A structure of real first-order factors fitted to a record with a complex pair of zeros
    stops with them equal.

    Examples
    --------
    >>> coinciding({"k": 30.7, "z1": 1.32449475, "z2": 1.32449465, "p1": 4.02, "p2": 3.0})[:60]
    'z1 and z2 met at 1.324: the model cannot tell them apart the'
    >>> coinciding({"k": 2.0, "p": 3.0})
    ''
    """
    names = [k for k, v in values.items() if np.isfinite(v) and v != 0.0]
    groups: list[list[str]] = []
    for name in names:
        group = next((g for g in groups if _meet(values[g[0]], values[name])), None)
        if group is None:
            groups.append([name])
        else:
            group.append(name)
    met = [g for g in groups if len(g) > 1]
    if not met:
        return ""
    listed = "; ".join(f"{', '.join(g[:-1])} and {g[-1]} met at {values[g[0]]:.4g}" for g in met)
    return f"{listed}: {_MET}"


@dataclass(frozen=True)
class WeakParameter:
    """A parameter the record cannot pin down.

    Attributes
    ----------
    name : str
    value, std : float
    relative_std : float
        ``std / |value|`` (for the delay ``std / max(|delay|, dt)``).
    interval : tuple of float
        The fit's 95 % interval.
    partner : str or None
        The parameter it is most correlated with.
    correlation : float
        That correlation.
    reason : str
        Why it is flagged, in words.
    """

    name: str
    value: float
    std: float
    relative_std: float
    interval: tuple[float, float]
    partner: str | None
    correlation: float
    reason: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields.

        Examples
        --------
        >>> w = WeakParameter("z", 1.0, 0.6, 0.6, (-0.2, 2.2), "p", 0.999, "std 60 % of the value")
        >>> w.to_dict()["partner"], w.to_dict()["interval"]
        ('p', [-0.2, 2.2])
        """
        return {"name": self.name, "value": self.value, "std": self.std, "relative_std": self.relative_std,
                "interval": list(self.interval), "partner": self.partner, "correlation": self.correlation,
                "reason": self.reason}

    def text(self) -> str:
        """One line for a report.

        Examples
        --------
        >>> WeakParameter("z", 1.0, 0.6, 0.6, (-0.2, 2.2), "p", 0.999, "std 60 % of the value").text()
        'z = 1 is weakly identifiable (std 60 % of the value; correlation +0.999 with p; 95 % interval [-0.2, 2.2])'
        """
        partner = f"; correlation {self.correlation:+.3f} with {self.partner}" if self.partner else ""
        return (f"{self.name} = {self.value:.6g} is weakly identifiable ({self.reason}{partner}; "
                f"95 % interval [{self.interval[0]:.6g}, {self.interval[1]:.6g}])")


def weak_parameters(names: list[str], values: dict[str, float], covariance: np.ndarray,
                    intervals: dict[str, tuple[float, float]], delay_name: str | None = None,
                    dt: float = 0.0) -> list[WeakParameter]:
    """The weakly identifiable parameters of a fit (see the module text for the rule).

    Parameters
    ----------
    names : list of str
        Rows and columns of ``covariance`` (``"offset"`` is skipped).
    values : dict
        Fitted values by name.
    covariance : numpy.ndarray
    intervals : dict
        95 % intervals by name.
    delay_name : str, optional
        The delay's name (judged against ``max(|delay|, dt)``).
    dt : float
        Sample time [s].

    Returns
    -------
    list of WeakParameter
        Empty when every parameter is pinned down.

    Examples
    --------
    >>> cov = np.array([[0.04, 0.03992], [0.03992, 0.04]])  # std 0.2 each, correlation 0.998
    >>> weak = weak_parameters(["z", "p"], {"z": 1.0, "p": 1.1}, cov, {"z": (0.6, 1.4), "p": (0.7, 1.5)})
    >>> [(w.name, w.partner, round(w.correlation, 3)) for w in weak]
    [('z', 'p', 0.998), ('p', 'z', 0.998)]
    >>> weak_parameters(["k", "p"], {"k": 2.0, "p": 3.0}, np.diag([1e-4, 1e-4]), {"k": (1.98, 2.02), "p": (2.98, 3.02)})
    []
    >>> inf = float("inf")  # two zeros that met at the estimate: the Jacobian cannot tell them apart
    >>> weak = weak_parameters(["z1", "z2"], {"z1": 0.706, "z2": 0.706}, np.diag([inf, inf]), {})
    >>> weak[0].reason[:58]
    'it equals z2 at the estimate, and the model cannot tell th'
    """
    cov = np.asarray(covariance, float)
    idx = [i for i, n in enumerate(names) if n != "offset"]
    if not idx or cov.shape != (len(names), len(names)):
        return []
    sd, corr = _std_and_correlation(cov)
    out = []
    for i in idx:
        name = names[i]
        value = float(values[name])
        ref = max(abs(value), dt) if name == delay_name else abs(value)
        rel = float(sd[i] / ref) if ref > 0 else (float("inf") if sd[i] > 0 else 0.0)
        others = [j for j in idx if j != i and np.isfinite(corr[i, j])]
        j = max(others, key=lambda k: abs(corr[i, k])) if others else None
        rho = float(corr[i, j]) if j is not None else 0.0
        twin = next((names[k] for k in idx if k != i and not np.isfinite(sd[k])
                     and _meet(value, float(values[names[k]]), 1e-6)), None)
        if not np.isfinite(sd[i]) and twin is not None:
            reason = f"it equals {twin} at the estimate, and {_MET}"
        elif not np.isfinite(sd[i]):
            reason = "its standard error is not finite"
        elif rel > WEAK_RELATIVE_STD:
            reason = f"std {100 * rel:.3g} % of {_reference(value, ref, dt)}"
        elif abs(rho) >= TIED_CORRELATION and rel > TIED_RELATIVE_STD:
            reason = f"std {100 * rel:.3g} % of {_reference(value, ref, dt)}, tied to another parameter"
        else:
            continue
        lo, hi = intervals.get(name, (float("nan"), float("nan")))
        out.append(WeakParameter(name, value, float(sd[i]), rel, (float(lo), float(hi)),
                                 names[j] if j is not None else None, rho, reason))
    return out


@dataclass(frozen=True)
class TiedParameter:
    """A parameter the rule does not flag whose standard error still rests on a weak one's.

    With ``|correlation| >= TIED_TO_WEAK`` (0.9: at least 81 % of its linearized variance lies along the weak
    parameter's direction), its interval comes from the same linearization that fails along the weak
    parameter's ridge: where the pair wanders far along it, this parameter moves with it (the Cramer-Rao
    benchmark's near cancellations: gains scattering 2.7-8.4 times their bound, their reported standard
    errors a quarter to seven times that scatter).

    Attributes
    ----------
    name : str
    value, std : float
    partner : str
        The weak parameter it is most correlated with.
    correlation : float
        That correlation.
    """

    name: str
    value: float
    std: float
    partner: str
    correlation: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields.

        Examples
        --------
        >>> TiedParameter("k", 4.0, 0.1, "z", 0.97).to_dict()["partner"]
        'z'
        """
        return {"name": self.name, "value": self.value, "std": self.std, "partner": self.partner,
                "correlation": self.correlation}

    def text(self) -> str:
        """One line for a report.

        Examples
        --------
        >>> TiedParameter("k", 4.0, 0.1, "z", 0.97).text()[:64]
        'k = 4 (std 0.1) moves with weakly identifiable z (correlation +0'
        """
        return (f"{self.name} = {self.value:.6g} (std {self.std:.3g}) moves with weakly identifiable {self.partner} "
                f"(correlation {self.correlation:+.3f}): its standard error rests on the same linearization and "
                "is not reliable either")


def tied_to_weak(names: list[str], values: dict[str, float], covariance: np.ndarray,
                 weak: list[WeakParameter]) -> list[TiedParameter]:
    """The parameters not in ``weak`` whose correlation with one of them is at least :data:`TIED_TO_WEAK`.

    Examples
    --------
    >>> cov = np.array([[1e-4, 0.0095, 0.0], [0.0095, 1.0, 0.0], [0.0, 0.0, 1e-4]])  # k tied to z (0.95)
    >>> weak = weak_parameters(["k", "z", "p"], {"k": 2.0, "z": 1.0, "p": 3.0}, cov, {})
    >>> [w.name for w in weak], [(t.name, t.partner, round(t.correlation, 2))
    ...                          for t in tied_to_weak(["k", "z", "p"], {"k": 2.0, "z": 1.0, "p": 3.0}, cov, weak)]
    (['z'], [('k', 'z', 0.95)])
    """
    cov = np.asarray(covariance, float)
    flagged = {w.name for w in weak}
    if not flagged or cov.shape != (len(names), len(names)):
        return []
    sd, corr = _std_and_correlation(cov)
    out = []
    for i, name in enumerate(names):
        if name in flagged or name == "offset":
            continue
        links = [(abs(corr[i, j]), j) for j, other in enumerate(names) if other in flagged and np.isfinite(corr[i, j])]
        if not links:
            continue
        size, j = max(links)
        if size >= TIED_TO_WEAK:
            out.append(TiedParameter(name, float(values[name]), float(sd[i]), names[j], float(corr[i, j])))
    return out


def _reference(value: float, ref: float, dt: float) -> str:
    """What a relative std is relative to: the value, or one sample interval for a delay shorter than one (a delay
    fitted at 0 was "std 30.8 % of the value").

    Examples
    --------
    >>> _reference(0.5, 0.5, 0.01), _reference(0.0, 0.01, 0.01)
    ('the value', 'one sample interval (0.01 s; the delay is shorter)')
    """
    return "the value" if ref == abs(value) else f"one sample interval ({dt:.3g} s; the delay is shorter)"


def _std_and_correlation(cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Standard errors and the correlation matrix of a covariance (nan where a standard error is 0)."""
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(all="ignore"):
        return sd, cov / np.outer(sd, sd)
