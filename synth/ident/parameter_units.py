"""The unit of each parameter of a structure, by dimensional analysis of its transfer function.

A transfer function is the same physical function whatever the unit of time: scaling every frequency by ``lam``
(``s -> lam s``) and each parameter by ``lam`` to the power of its time dimension ``a_i`` leaves ``H`` unchanged, so
``s dH/ds + sum_i a_i theta_i dH/dtheta_i = 0`` at every ``s`` and ``theta``. Likewise a gain carries the output
per input: ``sum_i b_i theta_i dH/dtheta_i = H``. Both are linear in the exponents; they are solved by least
squares on random points and kept only where the solution is unique and integer (``k/(s+p)``: ``k`` in output per
input per second, ``p`` in rad/s; ``K/(T*s+1)``: ``T`` in s). Where the formula leaves an exponent undetermined
(``a*b/(s+p)``) that parameter gets no unit.
"""

from __future__ import annotations

import numpy as np

from synth.ident.structure import Structure, parse_structure

__all__ = ["parameter_units"]


def _log_derivatives(structure: Structure, theta: np.ndarray, tau: float, s: np.ndarray) -> tuple[np.ndarray, ...]:
    """``H``, ``s dH/ds`` and the columns ``theta_i dH/dtheta_i`` (the delay's last), by central differences."""

    def H(th: np.ndarray, delay: float, ss: np.ndarray) -> np.ndarray:
        num, den = structure.coefficients(th)
        return np.polyval(num, ss) / np.polyval(den, ss) * np.exp(-delay * ss)

    h = 1e-6
    base = H(theta, tau, s)
    ds = (H(theta, tau, s * (1 + h)) - H(theta, tau, s * (1 - h))) / (2 * h)
    columns = []
    for i in range(theta.size):
        up, down = theta.copy(), theta.copy()
        up[i], down[i] = theta[i] * (1 + h), theta[i] * (1 - h)
        columns.append((H(up, tau, s) - H(down, tau, s)) / (2 * h))
    if isinstance(structure.delay, str):
        columns.append((H(theta, tau * (1 + h), s) - H(theta, tau * (1 - h), s)) / (2 * h))
    return base, ds, np.column_stack(columns)


def _exponents(A: np.ndarray, rhs: np.ndarray) -> list[int | None]:
    """Integer least-squares solution of ``A x = rhs`` (complex rows); None for an unknown the equations leave open
    (a component of their null space) or that is not an integer, all None where they have no solution."""
    M, b = np.vstack([A.real, A.imag]), np.r_[rhs.real, rhs.imag]
    scale = np.linalg.norm(M, axis=0)
    scale[scale == 0] = 1.0
    x, *_ = np.linalg.lstsq(M / scale, b, rcond=None)
    if np.linalg.norm((M / scale) @ x - b) > 1e-5 * max(np.linalg.norm(b), 1.0):
        return [None] * A.shape[1]
    _, sv, vt = np.linalg.svd(M / scale)
    null = vt[np.r_[sv, np.zeros(vt.shape[0] - sv.size)] <= 1e-6 * sv[0]]
    x = x / scale
    return [int(np.rint(v)) if abs(v - np.rint(v)) < 1e-4 and not np.any(np.abs(null[:, i]) > 1e-6) else None
            for i, v in enumerate(x)]


def _text(time: int | None, gain: int | None, input_unit: str, output_unit: str) -> str | None:
    if time is None or gain is None or gain not in (-1, 0, 1):
        return None
    out, inp = (output_unit or "output", input_unit or "input")[::gain or 1]  # -1: input per output
    per = (f"({out})" if "/" in out else out) + "/" + (f"({inp})" if "/" in inp else inp) if gain else ""
    frequency = "" if time == 0 else ("rad/s" if time == 1 else f"(rad/s)^{time}" if time > 1
                                      else "s" if time == -1 else f"s^{-time}")
    return f"{per}*{frequency}" if per and frequency else per or frequency


def parameter_units(structure: Structure | str, input_unit: str = "", output_unit: str = "") -> dict[str, str]:
    """Each parameter's unit (the delay's too, ``s``); a parameter whose dimension the formula leaves open, or
    whose unit is not a power of time times at most one output per input (or input per output), is left out.

    Parameters
    ----------
    structure : Structure or str
        The formula.
    input_unit, output_unit : str
        The record's units ("" where unknown: the text then says ``output/input``).

    Returns
    -------
    dict of str to str

    Examples
    --------
    >>> parameter_units("k*exp(-Td*s)/((s+p1)*(s+p2))", "V", "rad/s")
    {'k': '(rad/s)/V*(rad/s)^2', 'p1': 'rad/s', 'p2': 'rad/s', 'Td': 's'}
    >>> parameter_units("K/((T1*s+1)*(T2*s+1))", "PWM", "rpm")
    {'K': 'rpm/PWM', 'T1': 's', 'T2': 's'}
    >>> parameter_units("k*exp(-Td*s)/(s^2+2*z*w*s+w^2)")
    {'k': 'output/input*(rad/s)^2', 'z': '', 'w': 'rad/s', 'Td': 's'}
    """
    st = structure if isinstance(structure, Structure) else parse_structure(structure)
    names = [*st.parameters, *([st.delay] if isinstance(st.delay, str) else [])]
    rng = np.random.default_rng(0)
    rows, rhs_time, rhs_gain = [], [], []  # both systems share the matrix; only the right-hand sides differ
    for _ in range(4):
        theta = rng.uniform(0.5, 2.0, len(st.parameters))
        tau = float(rng.uniform(0.05, 0.2)) if isinstance(st.delay, str) else 0.0  # a fixed delay: no parameter
        s = 1j * np.geomspace(0.3, 3.0, 6) + rng.uniform(0.1, 0.5)
        try:
            with np.errstate(all="ignore"):
                H, ds, cols = _log_derivatives(st, theta, tau, s)
        except (ValueError, ZeroDivisionError, ArithmeticError):
            return {}
        if not (np.all(np.isfinite(H)) and np.all(np.isfinite(cols)) and np.all(np.abs(H) > 0)):
            return {}
        rows.append(cols / H[:, None])
        rhs_time.append(-ds / H)
        rhs_gain.append(np.ones(s.size, complex))
    cols = len(names) if isinstance(st.delay, str) else len(st.parameters)
    matrix = np.vstack(rows)[:, :cols]
    time = _exponents(matrix, np.concatenate(rhs_time))
    gain = _exponents(matrix, np.concatenate(rhs_gain))
    units = {}
    for name, a, b in zip(names, time, gain):
        text = _text(a, b, input_unit, output_unit)
        if text is not None:
            units[name] = text
    return units
