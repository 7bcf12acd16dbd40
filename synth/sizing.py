"""Rotor and drive sizing by momentum theory (X-4 paper, sections 2-3), and its reconciliation with the paper.

Formulas (hover, ideal rotor):

- thrust per rotor ``T = m g (1 + margin) / n``;
- disc area ``A = pi R^2``; induced velocity ``v_i = sqrt(T / (2 rho A))``;
- induced power (eq. 1) ``P_i = T^1.5 / sqrt(2 rho A) = T v_i``;
- figure of merit (eq. 2) ``FM = P_i / P_s``, ``P_s`` the shaft power;
- torque constant ``k_t = Q_max / I_max`` (the paper's 0.1749 N m at 22 A); shaft power at speed
  ``P_s = Q_max w``; the largest thrust that shaft power lifts at ``FM = 1``:
  ``T_max = (P_s sqrt(2 rho A))^(2/3)``;
- battery: ``V = cells in series x cell voltage``, ``I = strings x cell current``, ``P_e = V I``.

Defaults are the paper's numbers; the air density defaults to the ISA sea-level 1.225 kg/m^3 (the
paper does not state the density it used; its 101.2 W implies about 1.169 kg/m^3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

from synth.errors import ModelError
from synth.paper_row import PaperRow

__all__ = ["G_STANDARD", "RHO_SEA_LEVEL", "UNITS", "RotorSizing", "density_for_power", "induced_power", "isa_altitude",
           "rotor_sizing", "sizing_checks", "thrust_for_power"]

#: standard gravity [m/s^2]
G_STANDARD = 9.80665
#: ISA sea-level air density [kg/m^3]
RHO_SEA_LEVEL = 1.225

UNITS = {
    "mass": "kg", "margin": "1", "rotors": "1", "thrust": "N", "radius": "m", "rho": "kg/m^3", "area": "m^2",
    "induced_velocity": "m/s", "induced_power": "W", "speed": "rad/s", "current_limit": "A", "max_torque": "N m",
    "torque_constant": "N m/A", "shaft_power": "W", "max_thrust_ideal": "N", "required_figure_of_merit": "1",
    "torque_for_induced_power": "N m", "current_for_induced_power": "A", "cells_series": "1", "strings": "1",
    "cell_voltage": "V", "cell_current": "A", "battery_voltage": "V", "battery_current": "A",
    "battery_power": "W", "electrical_power_at_limit": "W", "shaft_over_electrical": "1",
}


@dataclass(frozen=True)
class RotorSizing:
    """Momentum-theory sizing of one rotor and its drive (units in :data:`UNITS`; see the module text).

    Examples
    --------
    >>> s = rotor_sizing()
    >>> round(s.thrust, 3), round(s.induced_power, 2), round(s.shaft_power, 1)
    (12.749, 99.44, 139.9)
    >>> s.to_dict()["induced_power"]["unit"]
    'W'
    """

    mass: float
    margin: float
    rotors: int
    thrust: float
    radius: float
    rho: float
    area: float
    induced_velocity: float
    induced_power: float
    speed: float
    current_limit: float
    max_torque: float
    torque_constant: float
    shaft_power: float
    max_thrust_ideal: float
    required_figure_of_merit: float
    torque_for_induced_power: float
    current_for_induced_power: float
    cells_series: int
    strings: int
    cell_voltage: float
    cell_current: float
    battery_voltage: float
    battery_current: float
    battery_power: float
    electrical_power_at_limit: float
    shaft_over_electrical: float

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """Every number as ``{"value": ..., "unit": ...}``."""
        return {f.name: {"value": getattr(self, f.name), "unit": UNITS[f.name]} for f in fields(self)}


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise ModelError(f"sizing: {name} must be > 0, got {value!r}")
    return value


def induced_power(thrust: float, radius: float, rho: float) -> float:
    """Ideal induced power in hover, eq. 1: ``T^1.5 / sqrt(2 rho pi R^2)`` [W].

    Examples
    --------
    >>> round(induced_power(12.7, 0.165, RHO_SEA_LEVEL), 2)
    98.87
    """
    return thrust**1.5 / math.sqrt(2 * rho * math.pi * radius**2)


def thrust_for_power(power: float, radius: float, rho: float = RHO_SEA_LEVEL) -> float:
    """Thrust an ideal rotor (FM = 1) lifts with ``power`` watts: ``(P sqrt(2 rho A))^(2/3)`` [N].

    Examples
    --------
    >>> round(thrust_for_power(131.0, 0.165), 2), round(thrust_for_power(131.0, 0.165, 1.169), 2)
    (15.32, 15.08)
    """
    return (_positive("power", power) * math.sqrt(2 * rho * math.pi * _positive("radius", radius) ** 2)) ** (2 / 3)


def density_for_power(thrust: float, radius: float, power: float) -> float:
    """Air density at which ``thrust`` needs ``power`` of induced power: ``T^3 / (2 A P^2)`` [kg/m^3].

    Examples
    --------
    >>> round(density_for_power(12.7, 0.165, 101.2), 4)
    1.1693
    """
    area = math.pi * _positive("radius", radius) ** 2
    return _positive("thrust", thrust) ** 3 / (2 * area * _positive("power", power) ** 2)


def isa_altitude(rho: float) -> float:
    """Altitude [m] of the ISA troposphere where the density is ``rho`` (``1.225 (1 - 2.25577e-5 h)^4.2559``).

    Examples
    --------
    >>> round(isa_altitude(1.1693))
    482
    """
    return (1 - (_positive("rho", rho) / RHO_SEA_LEVEL) ** (1 / 4.2559)) / 2.25577e-5


def rotor_sizing(mass: float = 4.0, margin: float = 0.30, rotors: int = 4, radius: float = 0.165,
                 rho: float = RHO_SEA_LEVEL, speed: float = 800.0, current_limit: float = 22.0,
                 max_torque: float = 0.1749, thrust: float | None = None, cells_series: int = 4, strings: int = 2,
                 cell_voltage: float = 3.7, cell_current: float = 12.0, g: float = G_STANDARD) -> RotorSizing:
    """Momentum-theory sizing of one rotor and its drive (defaults: the X-4 paper, sections 2-3).

    Parameters
    ----------
    mass : float
        Craft mass [kg] (4 kg).
    margin : float
        Control margin on the hover thrust (0.30).
    rotors : int
        Number of rotors (4).
    radius : float
        Rotor radius [m] (0.165 m).
    rho : float
        Air density [kg/m^3]; default ISA sea level 1.225 (the paper states none).
    speed : float
        Operating rotor speed [rad/s] (800 rad/s, sec. 3).
    current_limit : float
        Motor current limit [A] (22 A, sec. 3).
    max_torque : float
        Motor torque at the current limit [N m] (0.1749 N m, sec. 3).
    thrust : float, optional
        Thrust per rotor [N]; default ``mass g (1 + margin) / rotors``.
    cells_series, strings : int
        Battery: cells in series per string (4) and parallel strings (2), sec. 2.
    cell_voltage, cell_current : float
        Nominal cell voltage [V] (3.7) and continuous cell current [A] (12), sec. 2.
    g : float
        Gravity [m/s^2] (standard 9.80665).

    Returns
    -------
    RotorSizing

    Raises
    ------
    ModelError
        A non-positive or non-finite input.

    Examples
    --------
    >>> s = rotor_sizing(thrust=12.7, rho=1.169)
    >>> round(s.induced_power, 1), round(s.required_figure_of_merit, 3), s.battery_current
    (101.2, 0.723, 24.0)
    >>> rotor_sizing(radius=0)
    Traceback (most recent call last):
    synth.errors.ModelError: sizing: radius must be > 0, got 0.0
    """
    for name, value in (("mass", mass), ("radius", radius), ("rho", rho), ("speed", speed),
                        ("current_limit", current_limit), ("max_torque", max_torque), ("cell_voltage", cell_voltage),
                        ("cell_current", cell_current), ("g", g), ("rotors", rotors), ("cells_series", cells_series),
                        ("strings", strings)):
        _positive(name, value)
    if not (math.isfinite(margin) and margin >= 0):
        raise ModelError(f"sizing: margin must be >= 0, got {margin!r}")
    T = _positive("thrust", thrust) if thrust is not None else mass * g * (1 + margin) / rotors
    area = math.pi * radius**2
    p_i = induced_power(T, radius, rho)
    k_t = max_torque / current_limit
    p_s = max_torque * speed
    v_bat = cells_series * cell_voltage
    i_bat = strings * cell_current
    p_limit = v_bat * current_limit
    return RotorSizing(
        mass=float(mass), margin=float(margin), rotors=int(rotors), thrust=float(T), radius=float(radius),
        rho=float(rho), area=area, induced_velocity=math.sqrt(T / (2 * rho * area)), induced_power=p_i,
        speed=float(speed), current_limit=float(current_limit), max_torque=float(max_torque), torque_constant=k_t,
        shaft_power=p_s, max_thrust_ideal=thrust_for_power(p_s, radius, rho), required_figure_of_merit=p_i / p_s,
        torque_for_induced_power=p_i / speed, current_for_induced_power=p_i / speed / k_t,
        cells_series=int(cells_series), strings=int(strings), cell_voltage=float(cell_voltage),
        cell_current=float(cell_current), battery_voltage=v_bat, battery_current=i_bat, battery_power=v_bat * i_bat,
        electrical_power_at_limit=p_limit, shaft_over_electrical=p_s / p_limit)


def sizing_checks(rho: float = RHO_SEA_LEVEL) -> list[PaperRow]:
    """The paper's section 2-3 (and 4B) numbers beside synth's momentum-theory values.

    Every synth value is computed here from the paper's inputs (4 kg, 30 %, 4 rotors, 0.165 m, 800 rad/s,
    22 A, 0.1749 N m, 4 x 2 cells of 3.7 V / 12 A / 15 A burst, built rotor 14.3 N at about 1000 rad/s
    with FM 0.71, hover at 850 rad/s) with the air density ``rho``.

    Examples
    --------
    >>> rows = {r.quantity: r for r in sizing_checks()}
    >>> r = rows["induced power for 12.7 N"]; r.paper, round(r.synth, 2), r.status
    ('101.2', 98.87, 'does not reconcile')
    >>> round(rows["shaft power 131 W / 0.1749 N m: speed"].synth, 1)
    749.0
    """
    paper = rotor_sizing(rho=rho)  # the paper's inputs at density rho
    R, T_p, P_p, Q, P_s_p = 0.165, 12.7, 101.2, 0.1749, 131.0
    rho_implied = density_for_power(T_p, R, P_p)
    p_i = induced_power(T_p, R, rho)
    rows = [
        PaperRow.compare("thrust per rotor", "12.7", paper.thrust, "N", "sec. 3",
                         f"4 kg x 1.3 x {G_STANDARD} m/s^2 / 4 = {paper.thrust:.4g} N (with g = 9.81: 12.75 N, "
                         "which rounds to 12.8)"),
        PaperRow.compare("induced power for 12.7 N", "101.2", p_i, "W", "sec. 3, eq. 1",
                         f"eq. 1 with rho = {rho:g} kg/m^3 on a 0.165 m rotor gives {p_i:.4g} W; 101.2 W needs "
                         f"rho = {rho_implied:.4g} kg/m^3 (ISA at about {isa_altitude(rho_implied):.0f} m, or a warm "
                         "day); the paper states no density"),
        PaperRow.derived("air density implied by 101.2 W", rho_implied, "kg/m^3", "sec. 3, eq. 1",
                         f"T^3 / (2 A P_i^2) with T = 12.7 N, P_i = 101.2 W; synth's default is the ISA sea-level "
                         f"{RHO_SEA_LEVEL} kg/m^3"),
        PaperRow.compare("top shaft power at 800 rad/s", "131", paper.shaft_power, "W", "sec. 3",
                         f"0.1749 N m x 800 rad/s = {paper.shaft_power:.4g} W; 131 W = 0.1749 N m x "
                         f"{P_s_p / Q:.1f} rad/s (about 750 rad/s, not the stated 800)"),
        PaperRow.compare("shaft power 131 W / 0.1749 N m: speed", "800", P_s_p / Q, "rad/s", "sec. 3",
                         "the speed at which 0.1749 N m makes 131 W; 800 rad/s would need 131 W / 800 = 0.1638 N m"),
        PaperRow.compare("current limit", "22", paper.battery_current, "A", "sec. 3 vs sec. 2",
                         f"sec. 2: two parallel strings of 12 A cells = {paper.battery_current:g} A (15 A bursts: "
                         f"{2 * 15:g} A); 22 A is 1 A per string below; 24 A would give "
                         f"{24 * paper.torque_constant:.4g} N m at the same torque constant"),
        PaperRow.compare("largest ideal thrust at 131 W (FM = 1)", "15.1", thrust_for_power(P_s_p, R, rho), "N", "sec. 3",
                         f"(P sqrt(2 rho A))^(2/3) with rho = {rho:g}; 15.1 N follows with the implied "
                         f"rho = {rho_implied:.4g} ({thrust_for_power(P_s_p, R, rho_implied):.4g} N); at 800 rad/s "
                         f"({paper.shaft_power:.4g} W) it would be {thrust_for_power(paper.shaft_power, R, rho):.4g} N"),
        PaperRow.compare("least figure of merit", "0.77", p_i / P_s_p, "1", "sec. 3, eq. 2",
                         f"P_i / 131 W with P_i at rho = {rho:g}; the paper's 101.2 W / 131 W = {P_p / P_s_p:.4f}; "
                         f"with the 800 rad/s shaft power: {P_p / paper.shaft_power:.3f}"),
    ]
    built_pi = induced_power(14.3, R, rho)
    built_ps = built_pi / 0.71
    rows += [
        PaperRow.compare("built rotor: shaft power (14.3 N, FM 0.71)", "131", built_ps, "W", "sec. 3",
                         f"P_i(14.3 N) / 0.71 = {built_pi:.4g} / 0.71 W, more than the 131 W 'top shaft power'; it "
                         f"fits only at the higher speed: 0.1749 N m x 1000 rad/s = {Q * 1000:.4g} W "
                         f"({built_ps / 1000:.4g} N m, {built_ps / 1000 / paper.torque_constant:.3g} A needed)"),
        PaperRow.compare("hover speed of the built rotor (T ~ w^2)", "850", 1000 * math.sqrt(
            4.0 * G_STANDARD / 4 / 14.3), "rad/s", "sec. 3 and 4B",
                         "w = 1000 rad/s x sqrt(9.81 N / 14.3 N), assuming thrust ~ speed^2 through the built "
                         "point; 850 rad/s would put 14.3 N at "
                         f"{850 * math.sqrt(14.3 / (4.0 * G_STANDARD / 4)):.0f} rad/s ('approximately 1000')",
                         approximate=True, tolerance=0.5),
        PaperRow.compare("battery voltage", "14.8", paper.battery_voltage, "V", "sec. 2", "4 cells x 3.7 V"),
        PaperRow.compare("battery current", "24", paper.battery_current, "A", "sec. 2", "2 strings x 12 A"),
        PaperRow.compare("cells for four drives", "32", 4 * paper.cells_series * paper.strings, "1", "sec. 2",
                         "4 drives x (4 in series x 2 strings); the paper does not say one pack per drive"),
        PaperRow.derived("battery power at the 22 A limit", paper.electrical_power_at_limit, "W", "sec. 2-3",
                         f"14.8 V x 22 A; the 131 W shaft power is {P_s_p / paper.electrical_power_at_limit:.0%} of "
                         "it (the paper states no motor or controller efficiency); motor rated > 300 W, 35 A"),
        PaperRow.derived("torque constant", paper.torque_constant, "N m/A", "sec. 3", "0.1749 N m / 22 A"),
    ]
    return rows
