"""The delay and sensor arguments of a time-domain fit (:func:`synth.ident.timefit.fit_structure`), checked."""

from __future__ import annotations

import numpy as np

from synth.errors import ModelError
from synth.ident.structure import Structure
from synth.plant import Plant

__all__ = ["as_sensor", "resolve_delay"]


def resolve_delay(st: Structure, delay: str | float | None) -> tuple[bool, float | None, str]:
    """Whether the delay is fitted, its fixed value (None when fitted) and its name.

    Examples
    --------
    >>> from synth.ident.structure import parse_structure
    >>> resolve_delay(parse_structure("k/(s+p)"), "fit"), resolve_delay(parse_structure("k*exp(-Td*s)/(s+p)"), 0.02)
    ((True, None, 'delay'), (False, 0.02, 'Td'))
    """
    name = st.delay_parameter or "delay"
    if isinstance(st.delay, float):
        if delay is not None:
            raise ModelError(f"structure {st.formula!r} fixes the delay at {st.delay:g} s; do not give a delay too")
        return False, st.delay, name
    if delay is None:
        return (True, None, name) if st.delay_parameter else (False, 0.0, name)
    if isinstance(delay, str):
        if delay.strip().lower() == "fit":
            return True, None, name
        try:
            delay = float(delay)
        except ValueError:
            raise ModelError(f"delay must be 'fit' or a number of seconds, got {delay!r}") from None
    if not np.isfinite(delay) or delay < 0:
        raise ModelError(f"delay must be 'fit' or a number >= 0 s, got {delay!r}")
    return False, float(delay), name


def as_sensor(sensor: Plant | str | None) -> Plant | None:
    """A known sensor as a :class:`~synth.plant.Plant` (a formula is parsed; None stays None).

    Examples
    --------
    >>> as_sensor("50/(s+50)").dc_gain(), as_sensor(None)
    (1.0, None)
    """
    if sensor is None:
        return None
    if not isinstance(sensor, Plant):
        try:
            sensor = Plant.from_string(sensor)
        except ModelError as exc:
            raise exc.located("sensor") from None
    unstable = [p for p in np.atleast_1d(sensor.poles()) if p.real > 0]
    if unstable:
        shown = ", ".join(f"{complex(p).real:.4g}" + (f"{complex(p).imag:+.4g}j" if complex(p).imag else "")
                          for p in unstable)
        raise ModelError(f"a known sensor must be stable; {sensor.to_string()} has pole(s) at {shown}",
                         where="sensor")
    return sensor
