"""A spec's plant identified from a measured record, with its uncertainty as plant variants.

A spec may give ``plant: {identify: {...}}`` instead of a transfer function.
The record is identified once per process (cached on the file's path, size
and modification time and the settings), and its result kept on disk between
runs (:mod:`synth.ident.result_cache`: keyed by the file's bytes, the settings
and the code), and the parameter covariance of the
fit is carried into the design: the requirements must hold on the identified
plant and on the plants at both ends of each principal axis of the
confidence ellipsoid (``2 n`` plants for ``n`` fitted parameters, the delay
included when it is fitted).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from synth.distributions import chi2_ppf
from synth.errors import ModelError, SynthError
from synth.plant import Plant, Signal

__all__ = ["BUILTIN_RECORDS", "IdentifySettings", "identify_plant", "resolve_data", "uncertainty_plants"]

#: data sources that synth generates itself; the name is written ``builtin:<name>`` in a spec
BUILTIN_RECORDS = {"x4_step_train": "SYNTHETIC X-4 rotor step train (seed 1, sec. 4B model; synth.ident.x4_record)"}


@dataclass(frozen=True)
class IdentifySettings:
    """What to identify: the record, its columns, the structure and the options of :func:`synth.ident.identify`."""

    data: str
    time: str | None
    input: str | None
    output: str | None
    structure: str
    delay: str | float | None
    sensor: str | None
    average: str
    confidence: float
    variants: bool


def resolve_data(data: str, base: Path | None) -> Path:
    """The file behind ``data``: ``builtin:<name>`` or a path relative to ``base`` (the spec's folder).

    Examples
    --------
    >>> resolve_data("runs/a.csv", Path("specs")).as_posix()
    'specs/runs/a.csv'
    """
    if data.startswith("builtin:"):
        name = data.removeprefix("builtin:")
        if name not in BUILTIN_RECORDS:
            raise ModelError(f"unknown builtin record {name!r}; available: {', '.join(BUILTIN_RECORDS)}")
        from synth.ident.x4_record import x4_step_train_path

        return x4_step_train_path()
    path = Path(data)
    return path if path.is_absolute() or base is None else base / path


@lru_cache(maxsize=16)
def _identify_cached(path: str, stamp: tuple[int, int], settings: IdentifySettings, input_unit: str,
                     output_unit: str, label: str) -> Any:
    from synth.data import load_record
    from synth.ident.identification import identify
    from synth.ident.result_cache import cached_result

    def compute() -> Any:
        record = load_record(path, settings.time, settings.input, settings.output,
                             input_unit=input_unit, output_unit=output_unit)
        # the design uses the fit and its covariance only: the up/down comparison (two more fits) is not needed
        return identify(replace(record, source=label), settings.structure, settings.delay, settings.sensor,
                        settings.average, compare_directions=False)

    return cached_result(Path(path), (settings, input_unit, output_unit, label), compute)


def identify_plant(settings: IdentifySettings, base: Path | None, input: Signal, output: Signal) -> Any:
    """Identify the record of ``settings`` (cached); returns :class:`synth.ident.identification.IdentifyResult`.

    Errors in the data or the fit are :class:`~synth.errors.SynthError` naming the file.
    """
    path = resolve_data(settings.data, base)
    try:
        st = path.stat()
    except OSError:
        raise ModelError("file not found", where=str(path)) from None
    try:
        # a builtin record is named as such (its cache path differs from machine to machine)
        label = (f"{settings.data} ({BUILTIN_RECORDS[settings.data.removeprefix('builtin:')]})"
                 if settings.data.startswith("builtin:") else settings.data)
        return _identify_cached(str(path), (st.st_size, st.st_mtime_ns), settings, input.unit, output.unit, label)
    except SynthError:
        raise
    except (ValueError, RuntimeError) as exc:  # a fit that cannot proceed on this record
        raise ModelError(f"identification failed: {exc}", where=str(path)) from None


def uncertainty_plants(result: Any, confidence: float, input: Signal, output: Signal) -> list[Plant]:
    """Plants at both ends of each principal axis of the ``confidence`` ellipsoid of the fitted parameters.

    The ellipsoid is ``(theta - theta_hat)^T P^-1 (theta - theta_hat) <= chi2_n(confidence)`` with
    ``P`` the parameter covariance of the fit (the output offset left out); a delay that would
    turn negative is clipped at 0.

    Examples
    --------
    >>> from synth.ident.identification import identify
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 4, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(s+3)"), t, u) + 0.01 * np.random.default_rng(0).standard_normal(t.size)
    >>> res = identify(record_from_arrays(t, u, y), "k/(s+p)", average="none")
    >>> plants = uncertainty_plants(res, 0.95, Signal(), Signal())
    >>> len(plants), all(abs(p.dc_gain() - 2 / 3) < 0.01 for p in plants)
    (4, True)
    """
    fit = result.fit
    st = fit.structure
    names = [n for n in fit.names if n != "offset"]
    idx = [fit.names.index(n) for n in names]
    P = np.asarray(fit.covariance)[np.ix_(idx, idx)]
    if not np.all(np.isfinite(P)) or P.size == 0:
        return []
    values, vectors = np.linalg.eigh(0.5 * (P + P.T))
    radius = float(np.sqrt(chi2_ppf(confidence, len(names))))
    delay_name = st.delay_parameter or "delay"
    centre = np.array([fit.parameters[n] for n in names])
    plants: list[Plant] = []
    for k in np.argsort(values)[::-1]:
        if values[k] <= 0:
            continue
        for sign, tag in ((-1.0, "-"), (1.0, "+")):
            theta = dict(zip(names, centre + sign * radius * np.sqrt(values[k]) * vectors[:, k]))
            delay = max(0.0, float(theta.pop(delay_name, fit.delay)))
            try:
                p = st.plant({n: theta[n] for n in st.parameters}, delay=delay, input=input, output=output,
                             label=f"identified, axis {len(plants) // 2 + 1}{tag}")
            except ModelError:
                continue
            plants.append(p)
    return plants
