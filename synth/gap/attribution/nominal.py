"""The nominal model as a structure in its own nonzero coefficients (monic denominator), for the joint re-fit
of :mod:`synth.gap.attribution.refit`: the formula, the coefficients' values, and the plant back from them."""

from __future__ import annotations

import numpy as np

from synth.errors import ModelError
from synth.plant import Plant

__all__ = ["free_coefficients", "monomial", "nominal_structure", "plant_from_values"]


def monomial(power: int) -> str:
    """``s^power`` as the structure parser reads it (``""`` for power 0).

    Examples
    --------
    >>> [monomial(k) for k in range(3)]
    ['', 's', 's^2']
    """
    return "" if power == 0 else ("s" if power == 1 else f"s^{power}")


def free_coefficients(coeffs: np.ndarray) -> np.ndarray:
    """Which coefficients of a polynomial (highest power first) a re-fit moves: the nonzero ones and the zeros
    between them (the damping of an undamped pair, ``s^2 + 4``: a value, not structure). Zeros below the lowest
    nonzero coefficient (an integrator, a zero at the origin) stay zero.

    Examples
    --------
    >>> free_coefficients(np.array([1.0, 0.0, 4.0])).tolist(), free_coefficients(np.array([1.0, 2.0, 0.0])).tolist()
    ([True, True, True], [True, True, False])
    """
    nonzero = np.flatnonzero(coeffs != 0.0)
    index = np.arange(coeffs.size)
    return (index >= nonzero[0]) & (index <= nonzero[-1]) if nonzero.size else np.zeros(coeffs.size, bool)


def nominal_structure(plant: Plant) -> tuple[str, dict[str, float]]:
    """Structure formula in the plant's free coefficients (:func:`free_coefficients`; monic denominator) and their
    values.

    Examples
    --------
    >>> nominal_structure(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"))[0]
    '(n1*s+n0)/(s^2+d1*s+d0)'
    >>> nominal_structure(Plant.from_string("2/(s*(0.5*s+1))"))
    ('(n0)/(s^2+d1*s)', {'n0': 4.0, 'd1': 2.0})
    >>> nominal_structure(Plant.from_string("1/(s^2+4)"))  # an undamped pair: its damping is re-fitted too
    ('(n0)/(s^2+d1*s+d0)', {'n0': 1.0, 'd1': 0.0, 'd0': 4.0})
    """
    num, den = plant.num, plant.den
    values: dict[str, float] = {}

    def poly(coeffs: np.ndarray, prefix: str, monic: bool) -> str:
        deg = coeffs.size - 1
        terms = []
        free = free_coefficients(coeffs)
        for i, c in enumerate(coeffs):
            power = deg - i
            if not free[i]:
                continue
            mono = monomial(power)
            if monic and i == 0:
                terms.append(mono or "1")
                continue
            name = f"{prefix}{power}"
            values[name] = float(c)
            terms.append(f"{name}*{mono}" if mono else name)
        return "+".join(terms) if terms else "0"

    text_num = poly(num, "n", False)
    text_den = poly(den, "d", True)
    if text_num == "0":
        raise ModelError("the nominal model is zero; nothing to re-fit", where="plant")
    return f"({text_num})/({text_den})", values


def plant_from_values(plant: Plant, values: dict[str, float], delay: float) -> Plant:
    """``plant`` with the coefficients of :func:`nominal_structure` set to ``values`` (those it does not free stay
    zero) and the delay ``delay`` (at least 0).

    Examples
    --------
    >>> G = Plant.from_string("2/(s*(0.5*s+1))")
    >>> P = plant_from_values(G, {"n0": 6.0, "d1": 3.0}, 0.01)
    >>> P.num.tolist(), P.den.tolist(), P.delay
    ([6.0], [1.0, 3.0, 0.0], 0.01)
    """
    num = np.array([values.get(f"n{plant.num.size - 1 - i}", 0.0) if free else 0.0
                    for i, free in enumerate(free_coefficients(plant.num))])
    den = np.array([1.0 if i == 0 else (values.get(f"d{plant.den.size - 1 - i}", 0.0) if free else 0.0)
                    for i, free in enumerate(free_coefficients(plant.den))])
    return Plant(num, den, max(0.0, delay), plant.input, plant.output, "re-fitted")
