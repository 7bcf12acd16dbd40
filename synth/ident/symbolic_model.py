"""Building blocks of the fitted model's simulation, for any numeric or casadi symbolic type: the
controllable canonical form, the series with a known sensor, and a Taylor matrix exponential."""

from __future__ import annotations

from typing import Any

import numpy as np

from synth.plant import Plant

__all__ = ["companion_form", "on_sample", "taylor_expm", "with_sensor"]


def companion_form(num: list[Any], den: list[Any]) -> tuple[list[list[Any]], list[Any], Any]:
    """Controllable canonical ``A`` (nested lists), ``C`` and ``D`` of ``num/den`` (any numeric type).

    Examples
    --------
    >>> A, C, D = companion_form([2.0], [1.0, 3.0, 2.0])  # 2/(s^2 + 3 s + 2)
    >>> A, C, D
    ([[0.0, 1.0], [-2.0, -3.0]], [2.0, 0.0], 0.0)
    """
    n = len(den) - 1
    lead = den[0]
    a = [d / lead for d in den[1:]]
    b = [0.0] * (n + 1 - len(num)) + [c / lead for c in num]
    D = b[0]
    r = [b[i + 1] - D * a[i] for i in range(n)]
    A = [[0.0] * n for _ in range(n)]
    for i in range(n - 1):
        A[i][i + 1] = 1.0
    for j in range(n):
        A[n - 1][j] = -a[n - 1 - j]
    C = [r[n - 1 - j] for j in range(n)]
    return A, C, D


def with_sensor(num: list[Any], den: list[Any], sensor: Plant | None) -> tuple[list[Any], list[Any]]:
    """``num/den`` in series with a known ``sensor`` (coefficient lists of any numeric type).

    Examples
    --------
    >>> with_sensor([2.0], [1.0, 1.0], Plant.from_string("3/(s+4)"))
    ([6.0], [1.0, 5.0, 4.0])
    """
    if sensor is None:
        return list(num), list(den)

    def mul(p: list[Any], q: np.ndarray) -> list[Any]:
        out: list[Any] = [0.0] * (len(p) + q.size - 1)
        for i, x in enumerate(p):
            for j, y in enumerate(q):
                out[i + j] = out[i + j] + x * float(y)
        return out

    return mul(list(num), sensor.num), mul(list(den), sensor.den)


def taylor_expm(M: Any, squarings: int, order: int = 12, symbolic: str = "MX") -> Any:
    """``exp(M)`` of a casadi matrix by scaling and squaring with a Taylor series of ``order`` terms
    (``symbolic``: the casadi type of the identity, ``"MX"`` or ``"SX"``).

    Examples
    --------
    >>> import casadi as ca
    >>> E = taylor_expm(ca.DM([[-1.0]]), 3, symbolic="SX")
    >>> round(float(ca.evalf(E)), 12) == round(float(np.exp(-1.0)), 12)
    True
    """
    import casadi as ca

    eye = getattr(ca, symbolic).eye
    n = M.shape[0]
    X = M / float(2**squarings)
    E = eye(n)
    for k in range(order, 0, -1):
        E = eye(n) + (X @ E) / k
    for _ in range(squarings):
        E = E @ E
    return E


def on_sample(fraction: float, dt: float) -> bool:
    """Whether a delay's fraction of a sample interval is zero (to 1e-9 of the interval): the delay is whole
    samples, and a biproper model's direct feedthrough sees the held input at the sample itself, ``u[k - m]``;
    with any fraction it sees the sample before, ``u[k - m - 1]``.

    Examples
    --------
    >>> on_sample(0.0, 0.01), on_sample(1e-15, 0.01), on_sample(0.002, 0.01)
    (True, True, False)
    """
    return abs(float(fraction)) <= 1e-9 * dt
