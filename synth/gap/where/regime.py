"""Where in the operating regime the residual lies: residual RMS in bins of a regime variable.

Regime variables (each sample of the record gets a value):

- ``amplitude``: ``|u - median(u)|``, the input's deviation from its operating point;
- ``rate``: ``sqrt(2)`` times the RMS of ``du/dt`` over a trailing window of four
  times the model's 63 % response time (about its 2 % settling time for a
  first-order model: an error caused by a fast input lasts about that long);
  for a sinusoid of amplitude ``A`` and frequency ``w`` (window of at least one
  period) this is ``A w``, and after a step it grows with the step size;
- ``operating_point``: the measured output level;
- ``direction``: direction of motion of the model output: ``up``/``down`` where
  ``|dy_model/dt|`` exceeds 2 % of its largest value, ``still`` elsewhere;
- every auxiliary channel of the record, by its value.

Continuous variables are cut into (up to) ``n_bins`` bins of equal sample
count (quantiles; ties collapse bins; when the smallest value holds at least
``1/n_bins`` of the samples, as the rate does between steps, it gets a bin of
its own and the rest is cut into ``n_bins - 1`` quantile bins). In each bin the mean square of the
residual is compared with the mean square over the rest of the record by
an F test, ``F = MS_bin / MS_rest`` with effective degrees of freedom
``n / (1 + 2 sum rho_k^2)`` (Bartlett's factor for the variance of a correlated
series, ``rho_k`` the residual's autocorrelation up to the first lag inside
``+-1.96/sqrt(N)``); a bin is flagged when the two-sided p-value is below
``(1 - level) / n_bins`` (Bonferroni over the bins of one variable). Bins
with fewer than 10 samples are not tested. A variable ``grows`` when its top
bin has the largest residual RMS and is flagged (significantly larger than
the rest) while the bottom bin is not flagged high; ``shrinks`` symmetrically.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.distributions import f_cdf, f_sf
from synth.errors import DataError
from synth.gap.where.residual import ModelResidual
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["MIN_BIN", "RegimeBin", "RegimeVariable", "bin_residual", "direction_of_motion", "input_rate", "localize_regime",
           "response_time"]

MIN_BIN = 10


@dataclass(frozen=True)
class RegimeBin:
    """Residual statistics in one bin of a regime variable.

    Examples
    --------
    >>> RegimeBin("0-1", 0.0, 1.0, 100, 0.5, 2.0, 1e-6, True).to_dict()["ratio"]
    2.0
    """

    label: str
    lo: float | None
    hi: float | None
    n: int
    rms: float
    ratio: float
    p_value: float | None
    flagged: bool

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        return {"label": self.label, "lo": self.lo, "hi": self.hi, "n": self.n, "rms": self.rms,
                "ratio": self.ratio, "p_value": self.p_value, "flagged": self.flagged}


@dataclass(frozen=True)
class RegimeVariable:
    """Residual RMS by bins of one regime variable.

    Attributes
    ----------
    name, description, unit : str
    bins : list of RegimeBin
    trend : str
        ``"grows"``, ``"shrinks"`` or ``"none"``.

    Examples
    --------
    >>> b = [RegimeBin("lo", 0, 1, 50, 0.1, 0.5, 0.001, True), RegimeBin("hi", 1, 2, 50, 0.4, 2.0, 0.001, True)]
    >>> v = RegimeVariable("rate", "input rate", "V/s", b, "grows")
    >>> v.flagged_high.label, v.contrast
    ('hi', 2.0)
    """

    name: str
    description: str
    unit: str
    bins: list[RegimeBin]
    trend: str

    @property
    def flagged_high(self) -> RegimeBin | None:
        """The flagged bin with the largest RMS ratio above 1, if any."""
        high = [b for b in self.bins if b.flagged and b.ratio > 1.0]
        return max(high, key=lambda b: b.ratio) if high else None

    @property
    def contrast(self) -> float:
        """Largest RMS ratio of a flagged bin (1 if none is flagged high)."""
        b = self.flagged_high
        return b.ratio if b else 1.0

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        return {"description": self.description, "unit": self.unit, "trend": self.trend,
                "flagged": [b.label for b in self.bins if b.flagged], "bins": [b.to_dict() for b in self.bins]}


def response_time(plant: Plant, dt: float) -> float:
    """The model's 63 % step-response time [s] (at least ``2 dt``; ``20 dt`` for a plant without steady state).

    Examples
    --------
    >>> round(response_time(Plant.from_string("1/(0.5*s+1)", delay=0.1), 0.001), 3)
    0.6
    """
    gain = plant.dc_gain()
    poles = np.roots(plant.den)
    if not np.isfinite(gain) or gain == 0.0 or np.any(poles.real >= 0):
        return 20.0 * dt
    slow = float(np.min(np.abs(poles.real))) if poles.size else 1.0 / dt
    n = int(min(2e5, max(50.0, (10.0 / slow + plant.delay) / dt)))
    t = np.arange(n) * dt
    y = simulate_plant(plant, t, np.ones(n), initial="zero") / gain
    above = np.flatnonzero(y >= 1.0 - np.exp(-1.0))
    t63 = float(t[above[0]]) if above.size else float(t[-1])
    return max(t63, 2.0 * dt)


def _neff_factor(e: np.ndarray) -> float:
    x = e - e.mean()
    n = x.size
    spec = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(np.abs(spec) ** 2)[:n]
    if acf[0] <= 0:
        return 1.0
    rho = acf / acf[0]
    inside = np.flatnonzero(np.abs(rho[1:]) < 1.96 / np.sqrt(n))
    K = int(inside[0]) if inside.size else n // 10
    K = min(K, n // 10)
    return float(1.0 + 2.0 * np.sum(rho[1: K + 1] ** 2))


def _test_bins(e2: np.ndarray, idx: np.ndarray, labels: list[str], bounds: list[tuple[float | None, float | None]],
               factor: float, level: float) -> list[RegimeBin]:
    nb = len(labels)
    out = []
    for j in range(nb):
        inb = idx == j
        n_in, n_out = int(inb.sum()), int((~inb).sum())
        if n_in == 0:
            continue
        ms_in = float(e2[inb].mean())
        ms_out = float(e2[~inb].mean()) if n_out else ms_in
        ratio = float(np.sqrt(ms_in / ms_out)) if ms_out > 0 else float("inf")
        p = None
        flagged = False
        if n_in >= MIN_BIN and n_out >= MIN_BIN and ms_out > 0:
            d1, d2 = max(n_in / factor, 1.0), max(n_out / factor, 1.0)
            F = ms_in / ms_out
            p = float(min(1.0, 2.0 * min(f_sf(F, d1, d2), f_cdf(F, d1, d2))))
            flagged = p < (1.0 - level) / nb
        out.append(RegimeBin(labels[j], bounds[j][0], bounds[j][1], n_in, float(np.sqrt(ms_in)), ratio, p, flagged))
    return out


def _trend(bins: list[RegimeBin]) -> str:
    if len(bins) < 2:
        return "none"
    rms = [b.rms for b in bins]
    top, bottom = bins[-1], bins[0]
    if top.flagged and top.ratio > 1 and top.rms == max(rms) and not (bottom.flagged and bottom.ratio > 1):
        return "grows"
    if bottom.flagged and bottom.ratio > 1 and bottom.rms == max(rms) and not (top.flagged and top.ratio > 1):
        return "shrinks"
    return "none"


def bin_residual(x: np.ndarray, e: np.ndarray, name: str, description: str = "", unit: str = "", n_bins: int = 5,
                 level: float = 0.95, factor: float | None = None) -> RegimeVariable | None:
    """Residual RMS in quantile bins of ``x``, with the F test of the module text (``None`` if ``x`` is constant).

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> x = rng.uniform(0, 1, 5000)
    >>> v = bin_residual(x, rng.normal(size=5000) * (1 + 3 * (x > 0.8)), "amplitude")
    >>> [b.flagged for b in v.bins], v.trend
    ([True, True, True, True, True], 'grows')
    """
    x = np.asarray(x, float)
    e = np.asarray(e, float)
    if x.shape != e.shape:
        raise DataError(f"regime variable '{name}' must have the residual's length", where=name)
    if np.ptp(x) <= 1e-12 * max(1.0, float(np.max(np.abs(x)))):
        return None
    lowest = float(x.min())
    at_min = x <= lowest
    if np.mean(at_min) >= 1.0 / n_bins and n_bins > 2:  # a mass at the minimum (rate 0 between steps): own bin
        rest = x[~at_min]
        q = np.unique(np.quantile(rest, np.linspace(0.0, 1.0, n_bins)))
        idx = np.zeros(x.size, int)
        if q.size == 1:
            idx[~at_min] = 1
            pairs = [(float(q[0]), float(q[0]))]
        else:
            idx[~at_min] = 1 + np.clip(np.searchsorted(q, rest, side="right") - 1, 0, q.size - 2)
            pairs = [(float(q[j]), float(q[j + 1])) for j in range(q.size - 1)]
        bounds = [(lowest, lowest), *pairs]
        labels = [f"{lo:.4g}" if lo == hi else f"{lo:.4g}-{hi:.4g}" for lo, hi in bounds]
    else:
        edges = np.unique(np.quantile(x, np.linspace(0.0, 1.0, n_bins + 1)))
        idx = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, edges.size - 2)
        labels = [f"{edges[j]:.4g}-{edges[j + 1]:.4g}" for j in range(edges.size - 1)]
        bounds = [(float(edges[j]), float(edges[j + 1])) for j in range(edges.size - 1)]
    factor = _neff_factor(e) if factor is None else factor
    bins = _test_bins(e**2, idx, labels, bounds, factor, level)
    return RegimeVariable(name, description or name, unit, bins, _trend(bins))


def direction_of_motion(y_model: np.ndarray, dt: float, dead_band: float = 0.02) -> np.ndarray:
    """``-1`` (down), ``0`` (still) or ``+1`` (up) per sample from the model output's slope.

    Examples
    --------
    >>> import numpy as np
    >>> direction_of_motion(np.array([0.0, 1.0, 2.0, 2.0, 2.0, 1.0]), 1.0).tolist()
    [1, 1, 1, 0, -1, -1]
    """
    slope = np.gradient(np.asarray(y_model, float), dt)
    big = np.max(np.abs(slope))
    if big == 0:
        return np.zeros(slope.size, int)
    out = np.sign(slope).astype(int)
    out[np.abs(slope) <= dead_band * big] = 0
    return out


def input_rate(u: np.ndarray, dt: float, window: float) -> np.ndarray:
    """``sqrt(2)`` times the trailing RMS of ``du/dt`` over ``window`` seconds (``A w`` for a sinusoid).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 20, 0.001)
    >>> round(float(np.median(input_rate(2.0 * np.sin(5.0 * t), 0.001, 2 * np.pi / 5.0))), 2)
    10.0
    """
    du = np.r_[0.0, np.diff(np.asarray(u, float))] / dt
    m = max(1, round(window / dt))
    c = np.cumsum(np.r_[0.0, du**2])
    k = np.arange(1, du.size + 1)
    lo = np.maximum(k - m, 0)
    return np.sqrt(2.0 * (c[k] - c[lo]) / (k - lo))


def localize_regime(residual: ModelResidual, plant: Plant, aux: dict[str, np.ndarray] | None = None,
                    n_bins: int = 5, level: float = 0.95, units: tuple[str, str] = ("", "")) -> dict[str, RegimeVariable]:
    """Residual by amplitude, input rate, operating point, direction of motion and aux channels.

    Parameters
    ----------
    residual : ModelResidual
    plant : Plant
        The model (its response time sets the rate window).
    aux : dict, optional
        Extra channels on the record's time base.
    n_bins : int
        Bins per continuous variable.
    level : float
        Family level of the bin tests of one variable.
    units : tuple of str
        Input and output units, for labels.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.where.residual import model_residual
    >>> t = np.arange(0, 50, 0.01)
    >>> rng = np.random.default_rng(0)
    >>> u = np.repeat(rng.uniform(-3, 3, 50), 100)
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> y = simulate_plant(G, t, np.clip(u, -2, 2)) + 0.02 * rng.normal(size=t.size)
    >>> reg = localize_regime(model_residual(G, record_from_arrays(t, u, y)), G)
    >>> reg["amplitude"].trend, reg["amplitude"].flagged_high.lo >= 1.5
    ('grows', True)
    """
    e, dt = residual.e, residual.dt
    uu, yu = units
    factor = _neff_factor(e)
    out: dict[str, RegimeVariable] = {}
    amp = np.abs(residual.u - np.median(residual.u))
    rate = input_rate(residual.u, dt, 4.0 * response_time(plant, dt))
    candidates = [("amplitude", amp, "input deviation from its median", uu),
                  ("rate", rate, "input rate A*w (sqrt 2 x trailing RMS of du/dt)", f"{uu}/s" if uu else "1/s"),
                  ("operating_point", residual.y, "measured output level", yu)]
    for key, value in (aux or {}).items():
        candidates.append((f"aux:{key}", np.asarray(value, float), f"auxiliary channel {key}", ""))
    for name, x, desc, unit in candidates:
        if np.asarray(x).shape != e.shape:
            raise DataError(f"must have the record's length {e.size}, got {np.asarray(x).size}", where=f"aux '{name}'")
        v = bin_residual(x, e, name, desc, unit, n_bins, level, factor)
        if v is not None:
            out[name] = v
    d = direction_of_motion(residual.y_model, dt)
    present = [k for k in (-1, 0, 1) if np.any(d == k)]
    if len(present) > 1:
        idx = np.array([present.index(k) for k in d])
        names = {-1: "down", 0: "still", 1: "up"}
        bins = _test_bins(e**2, idx, [names[k] for k in present], [(None, None)] * len(present), factor, level)
        out["direction"] = RegimeVariable("direction", "direction of motion of the model output", "", bins, "none")
    return out
