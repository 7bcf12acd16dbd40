"""Complex arithmetic on casadi expressions (real and imaginary parts carried separately).

casadi's symbolic types are real; frequency responses are complex. A
:class:`Cx` holds two casadi (or numpy) expressions and implements the few
operations the NLP needs, so that ``|1 + L(jw)|**2`` and friends are smooth
real expressions IPOPT can differentiate.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

__all__ = ["Cx", "delay_jw", "polyval_jw"]


@dataclass
class Cx:
    """``re + j im`` with casadi or numeric parts.

    Examples
    --------
    >>> z = Cx(1.0, 2.0) * Cx(3.0, -1.0)
    >>> float(z.re), float(z.im)
    (5.0, 5.0)
    """

    re: Any
    im: Any

    @staticmethod
    def of(value: complex | float) -> Cx:
        """Constant from a Python number."""
        v = complex(value)
        return Cx(v.real, v.imag)

    def __add__(self, other: Any) -> Cx:
        o = _cx(other)
        return Cx(self.re + o.re, self.im + o.im)

    __radd__ = __add__

    def __sub__(self, other: Any) -> Cx:
        o = _cx(other)
        return Cx(self.re - o.re, self.im - o.im)

    def __rsub__(self, other: Any) -> Cx:
        return _cx(other) - self

    def __mul__(self, other: Any) -> Cx:
        o = _cx(other)
        return Cx(self.re * o.re - self.im * o.im, self.re * o.im + self.im * o.re)

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> Cx:
        o = _cx(other)
        d = o.abs2()
        return Cx((self.re * o.re + self.im * o.im) / d, (self.im * o.re - self.re * o.im) / d)

    def __rtruediv__(self, other: Any) -> Cx:
        return _cx(other) / self

    def abs2(self) -> Any:
        """``|z|**2``."""
        return self.re * self.re + self.im * self.im

    def conj(self) -> Cx:
        """Complex conjugate."""
        return Cx(self.re, -self.im)


def _cx(x: Any) -> Cx:
    if isinstance(x, Cx):
        return x
    if isinstance(x, (complex, np.complexfloating)):
        return Cx(float(np.real(x)), float(np.imag(x)))
    return Cx(x, 0.0)


def polyval_jw(coeffs: Any, w: Any) -> Cx:
    """``p(j w)`` for coefficients in descending powers (numbers or casadi) and ``w`` number or casadi.

    Examples
    --------
    >>> z = polyval_jw([1.0, 2.0, 5.0], 3.0)  # (3j)^2 + 2(3j) + 5 = -4 + 6j
    >>> float(z.re), float(z.im)
    (-4.0, 6.0)
    """
    coeffs = list(coeffs)
    n = len(coeffs) - 1
    re, im = 0.0, 0.0
    for k, c in enumerate(coeffs):
        power = n - k
        wp = w ** power if power else 1.0
        phase = power % 4  # j^power = 1, j, -1, -j
        if phase == 0:
            re = re + c * wp
        elif phase == 1:
            im = im + c * wp
        elif phase == 2:
            re = re - c * wp
        else:
            im = im - c * wp
    return Cx(re, im)


def delay_jw(delay: float, w: Any) -> Cx:
    """``exp(-j w delay)``."""
    if delay == 0:
        return Cx(1.0, 0.0)
    cos, sin = (ca.cos, ca.sin) if isinstance(w, (ca.SX, ca.MX)) else (np.cos, np.sin)
    return Cx(cos(w * delay), -sin(w * delay))
