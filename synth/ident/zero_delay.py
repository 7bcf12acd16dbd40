"""A fitted delay of exactly zero for a model with a direct feedthrough.

The fitted delay is ``m dt + f`` with the fraction ``f`` in ``(0, dt]`` of sample interval ``m``
(:func:`synth.ident.delay_samples.walk_intervals`). A biproper model's feedthrough ``D`` sees the held input
``u[k - m - 1]`` anywhere in that interval and ``u[k]`` only at a delay of exactly 0, which no interval holds: on a
record of ``2 (s + 0.5)/(s + 3)`` without delay the fitted delay ended half a sample in, the fit 73 % with
residuals 40 times the noise, where the same structure with the delay held at 0 fits to the noise. So when the best
fitted delay lies in the first sample interval, the zero-delay fit is tried too and kept when it fits better,
reported as the fitted delay at its bound 0.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

__all__ = ["at_zero_delay", "zero_delay_candidate"]


def zero_delay_candidate(fitted: Any, dt: float) -> bool:
    """Whether a fitted delay's zero is worth a fit of its own: a direct feedthrough (biproper structure, no
    sensor) and the fitted delay within the first sample interval (``fitted`` a
    :class:`~synth.ident.timefit.TimeFitResult`, which imports this module).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.timefit import fit_structure
    >>> t = np.arange(0, 3, 0.01); u = (t >= 0.5) * 1.0
    >>> fit = fit_structure(record_from_arrays(t, u, u), "k/(s+p)", delay=0.0)
    >>> zero_delay_candidate(fit, 0.01)
    False
    """
    st = fitted.structure
    return (fitted.delay_fitted and fitted.sensor is None and st.num_degree >= st.den_degree
            and fitted.delay <= dt * (1.0 + 1e-9))


def at_zero_delay(zero: Any, fitted: Any) -> Any:
    """The fit with the delay held at 0 as a fitted delay at its bound: the delay's row and column (zeros) in the
    covariance, its name in ``names``, a note in ``solver["zero_delay"]`` with both fits.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.timefit import fit_structure
    >>> t = np.arange(0, 3, 0.01); u = (t >= 0.5) * 1.0
    >>> y = 2 * u - 1.5 * (1 - np.exp(-3 * (t - 0.5))) * u   # 2 (s + 0.75) / (s + 3), no delay
    >>> zero = fit_structure(record_from_arrays(t, u, y), "k*(s+z)/(s+p)", delay=0.0)
    >>> res = at_zero_delay(zero, zero)
    >>> res.delay_fitted, res.names, res.covariance.shape
    (True, ['k', 'z', 'p', 'delay', 'offset'], (5, 5))
    """
    p = len(zero.structure.parameters)
    name = zero.names[p] if zero.delay_fitted else (zero.structure.delay_parameter or "delay")
    if zero.delay_fitted:
        names, cov = list(zero.names), zero.covariance
    else:
        names = [*zero.names[:p], name, *zero.names[p:]]
        cov = np.insert(np.insert(zero.covariance, p, 0.0, axis=0), p, 0.0, axis=1)
    note = (f"the best delay is 0 s, at its bound: fit {zero.fit_percent:.2f} % there against "
            f"{fitted.fit_percent:.2f} % at the best delay above 0 ({fitted.delay:.4g} s); a direct feedthrough "
            "sees the held input's jump at the sample itself only at a delay of exactly 0")
    parameters = {**zero.parameters, name: 0.0}
    std = {**zero.std, name: 0.0}
    ci95 = {**zero.ci95, name: (0.0, 0.0)}
    return replace(zero, parameters=parameters, std=std, ci95=ci95, names=names, covariance=cov, delay=0.0,
                   delay_fitted=True, solver={**zero.solver, "zero_delay": note})
