"""The whole sim-to-real diagnosis in one call: where the gap lies, which effect explains it, how far.

:func:`diagnose` runs :func:`synth.gap.where.localize.localize_gap` (size of the gap
and where it lies, on the record) and
:func:`synth.gap.attribution.heldout.diagnose_effects` (nested augmentations judged on
held-out data) and returns one :class:`Diagnosis` whose ``to_dict()`` is the
JSON contract of ``synth diagnose --json``::

    {"gap": {"nrmse": 0.12, "fit_percent": 88.0, ...},
     "where": {"time_windows": [[t0, t1, share]], "frequency_bands": [[w0, w1, share]], "regimes": {...}},
     "effects": [{"effect": "rate_limit", "parameters": {"rate": 9800.0}, "shrinkage": 0.83,
                  "shrinkage_ci": [0.79, 0.86], "accepted": true, ...}],
     "verdict": {"effects": ["rate_limit"], "indistinguishable": [["delay", "lag"]], ...},
     "headline": "...", "summary": "...", "model": {...}, "record": {...}, "attribution": {...}}

``verdict.effects`` lists the accepted effects, most important first: ``[]``
when there is no gap (or none of the candidates explains it) and
``["parameter_mismatch"]`` when re-fitting the nominal coefficients was enough.

:func:`load_model` reads the model from a transfer-function string, a
``synth identify`` JSON or a spec file.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from synth.data.coerce import RecordLike, as_record
from synth.data.record import Record
from synth.errors import DataError, ModelError
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.attribution.verdict import EffectDiagnosis, aux_explained, not_carried
from synth.gap.effects.registry import DEFAULT_CANDIDATES, aux_candidates, make_effect
from synth.gap.heldout_warnings import heldout_warnings
from synth.gap.preflight import check_model
from synth.gap.verdict_sentence import verdict_sentence
from synth.gap.where.clipping import Clipping, record_clipping
from synth.gap.where.integrating import integrating_warning
from synth.gap.where.localize import GapLocalization, localize_gap
from synth.gap.where.residual import hidden_pulse_warnings, not_judged_warning
from synth.gap.where.start import start_transient_warning
from synth.ident.periodic_start import after_gaps
from synth.plant import Plant, Signal

__all__ = ["MODEL_FILE_SUFFIXES", "Diagnosis", "as_validation", "check_candidates", "diagnose", "heldout_warnings",
           "load_model"]

MODEL_FILE_SUFFIXES = (".json", ".yaml", ".yml")


def _plant_from_json(path: Path) -> Plant:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"cannot read the model file ({exc.__class__.__name__})", where=str(path)) from None
    except ValueError as exc:
        raise ModelError(f"not valid JSON ({exc})", where=str(path)) from None
    if not isinstance(data, dict):
        raise ModelError("expected a JSON object with 'plant' or 'tf' (as written by synth identify)", where=str(path))
    entry = data.get("plant")
    if isinstance(entry, dict) and "num" in entry and "den" in entry:
        try:
            num = np.asarray(entry["num"], float)
            den = np.asarray(entry["den"], float)
            delay = float(entry.get("delay", 0.0) or 0.0)
        except (TypeError, ValueError):
            raise ModelError("plant.num, plant.den and plant.delay must be numbers", where=f"{path}: plant") from None
        io = {k: Signal(str((entry.get(k) or {}).get("name", k[0])), str((entry.get(k) or {}).get("unit", "")))
              for k in ("input", "output") if isinstance(entry.get(k), dict)}
        try:
            return Plant(num, den, delay, label=str(entry.get("label", "")), **io)
        except ModelError as exc:
            raise exc.located(f"{path}: plant") from None
    if isinstance(data.get("tf"), str):
        try:
            plant = Plant.from_string(data["tf"])
            if plant.delay == 0.0 and data.get("delay"):  # the tf text carries exp(-d*s) when it has a delay
                plant = plant.with_delay(float(data["delay"]))
        except (ModelError, TypeError, ValueError) as exc:
            msg = exc.message if isinstance(exc, ModelError) else str(exc)
            raise ModelError(msg, where=f"{path}: tf") from None
        return plant
    raise ModelError("no 'plant' (with num, den, delay) or 'tf' key; expected the JSON of synth identify --json",
                     where=str(path))


def load_model(text: str, delay: float | None = None, where: str = "--plant") -> Plant:
    """The model from a transfer-function string, a ``synth identify`` JSON or a spec file.

    Parameters
    ----------
    text : str
        ``"23*(s+0.43)/((s+9.6)*(s+0.54))"``; or a ``.json`` file with a ``plant``
        entry (``num``, ``den``, ``delay``; :meth:`synth.plant.Plant.to_dict`) or a
        ``tf`` string, as ``synth identify --json`` writes; or a ``.yaml``/``.yml``
        spec file (its nominal plant).
    delay : float, optional
        Seconds. For a transfer-function string it is added to any ``exp(-T*s)``
        factor; for a file it replaces the file's delay.
    where : str
        Name of the option in error messages.

    Returns
    -------
    Plant

    Raises
    ------
    ModelError
        Unparsable transfer function, unusable JSON, negative delay.
    DataError
        A model file that does not exist.
    SpecError
        An invalid spec file.

    Examples
    --------
    >>> load_model("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02).delay
    0.02
    >>> load_model("specs/x4_rotor.yaml").to_string()
    '23*(s+0.43)/((s+9.6)*(s+0.54))'
    >>> load_model("2/(s+")
    Traceback (most recent call last):
    ...
    synth.errors.ModelError: --plant: ...
    """
    if delay is not None and (not np.isfinite(delay) or delay < 0):
        raise ModelError(f"delay must be a finite number >= 0 s, got {delay!r}", where="--delay")
    text = str(text).strip()
    path = Path(text)
    if path.suffix.lower() in MODEL_FILE_SUFFIXES:
        if not path.is_file():
            raise DataError("model file not found", where=f"{where} {text}")
        if path.suffix.lower() == ".json":
            plant = _plant_from_json(path)
        else:
            from synth.spec import load_spec

            plant = load_spec(path).nominal_plant()
        return plant if delay is None else plant.with_delay(float(delay))
    try:
        return Plant.from_string(text, delay=float(delay or 0.0))
    except ModelError as exc:
        raise exc.located(where) from None


@dataclass(frozen=True, eq=False)
class Diagnosis:
    """Size of the gap, where it lies, which effect explains it and how far it shrinks.

    Attributes
    ----------
    plant : Plant
        The nominal model.
    record : Record
        The record the gap is measured and localized on (and fitted on).
    validate : Record, tuple of Record, or None
        Held-out record (or runs), if given.
    localization : GapLocalization
    attribution : EffectDiagnosis
    clipping : tuple of Clipping
        Signals of the record (and the validation record) resting on their extreme value:
        direct evidence of a saturation (:mod:`synth.gap.where.clipping`).
    warnings : tuple of str
        What limits the held-out test (:func:`heldout_warnings`).

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 8, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> y = simulate_plant(G, t, u) + 0.01 * np.random.default_rng(1).normal(size=t.size)
    >>> d = diagnose(G, record_from_arrays(t, u, y), candidates=["delay"], n_null=3).to_dict()
    >>> d["verdict"]["effects"], sorted(d)[:4]
    ([], ['attribution', 'effects', 'gap', 'headline'])
    """

    plant: Plant
    record: Record
    validate: Record | tuple[Record, ...] | None
    localization: GapLocalization
    attribution: EffectDiagnosis
    clipping: tuple[Clipping, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def verdict(self) -> dict[str, Any]:
        """``effects``, ``indistinguishable``, ``experiments``, ``status``, ``headline``, ``observed``.

        ``effects`` are the effects accepted on held-out data; ``observed`` the effects seen
        directly in the data, whatever a model makes of them (a clipped signal: ``saturation``
        on the logged command, ``saturation(output)`` on the output).
        """
        observed = list(dict.fromkeys(c.effect for c in self.clipping))
        return {**self.attribution.verdict, "observed": observed}

    @property
    def summary(self) -> str:
        """The verdict in plain sentences (what to tell a person first), then any clipping seen in the data."""
        return self._verdict_sentence() + self._aux_sentence() + self._clipping_sentence()

    def _aux_sentence(self) -> str:
        """Which measured aux channel explained how much (its best effect's held-out shrinkage)."""
        parts = [f"{a['channel']} {a['shrinkage']:.2f} [{a['shrinkage_ci'][0]:.2f}, {a['shrinkage_ci'][1]:.2f}] "
                 f"({a['effect']}{', accepted' if a['accepted'] else ''})" for a in self.verdict.get("aux", [])]
        return f" Measured channels, held-out shrinkage beyond the re-fit: {'; '.join(parts)}." if parts else ""

    def _verdict_sentence(self) -> str:
        return verdict_sentence(self.verdict, self.attribution, self.localization.residual.nrmse, self.plant,
                                self.record)

    def _clipping_sentence(self) -> str:
        """What the clipped signals say, with the matching candidate's held-out shrinkage."""
        text = ""
        for clip in self.clipping:
            text += f" Seen in the data: {clip.describe()}."
        if "saturation(output)" in self.verdict["observed"]:
            fit = next((e for e in self.attribution.effects if e.effect == "saturation(output)"), None)
            if fit is not None and not fit.accepted:
                lo, hi = fit.shrinkage_ci
                text += (f" Adding the output clip to the model shrinks the held-out error by {fit.shrinkage:.2f} "
                         f"[{lo:.2f}, {hi:.2f}] ({'significant' if fit.significant else 'not significant'}), too "
                         "little to be accepted as the explanation of the gap.")
        return text

    def to_dict(self) -> dict[str, Any]:
        """The ``synth diagnose --json`` contract (JSON-serializable; non-finite numbers as strings).

        Keys: ``warnings`` (what limits the held-out test), ``gap``, ``where`` (with ``clipping``:
        signals resting on their extreme value),
        ``effects``, ``verdict`` (the contract, with ``observed``), and
        ``headline`` (where), ``summary`` (the verdict in a sentence), ``noise_floor``,
        ``model``, ``record``, ``validate``, ``attribution`` (re-fit, threshold, split).
        """
        from synth.outputs import to_jsonable

        loc = self.localization.to_dict()
        att = self.attribution.to_dict()
        units = {"input": self.record.input.unit, "output": self.record.output.unit}
        return to_jsonable({
            "warnings": list(self.warnings),
            "gap": loc["gap"], "where": {**loc["where"], "clipping": [c.to_dict() for c in self.clipping]},
            "effects": att["effects"], "verdict": self.verdict,
            "headline": loc["headline"], "summary": self.summary, "units": units,
            "noise_floor": {"variance": att["noise_floor"], "std": att["noise_std"]},
            "model": self.plant.to_dict(), "record": self.record.to_dict(),
            "validate": (None if self.validate is None else [v.to_dict() for v in self.validate]
                         if isinstance(self.validate, tuple) else self.validate.to_dict()),
            "attribution": {k: att[k] for k in ("j_nominal", "j_refit", "parameter_mismatch", "threshold", "split")},
        })


def check_candidates(candidates: list[str] | tuple[str, ...]) -> list[str]:
    """Validate candidate effect names (one-line :class:`ModelError` naming the unknown one).

    Examples
    --------
    >>> check_candidates(["rate_limit", " delay "])
    ['rate_limit', 'delay']
    >>> check_candidates(["ratelimit"])
    Traceback (most recent call last):
    ...
    synth.errors.ModelError: candidates: unknown effect 'ratelimit'; ...
    """
    names = [str(c).strip() for c in candidates if str(c).strip()]
    if not names:
        raise ModelError("give at least one candidate effect", where="candidates")
    for n in names:
        make_effect(n)
    if len(set(names)) != len(names):
        raise ModelError(f"repeated candidates in {names}", where="candidates")
    return names


def as_validation(validate: RecordLike | Sequence[RecordLike] | None) -> Record | tuple[Record, ...] | None:
    """The held-out data as records: one record, several runs (a tuple), or ``None``.

    A list or tuple of one-dimensional arrays is one record (``(t, u, y)``); any other list or tuple
    holds runs, each in any form :func:`synth.data.coerce.as_record` takes; a single run is one record.

    Parameters
    ----------
    validate : record-like, sequence of record-like, or None

    Returns
    -------
    Record, tuple of Record, or None

    Raises
    ------
    DataError
        A form that is not a record.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 1, 0.1); u = (t >= 0.3).astype(float)
    >>> as_validation((t, u, 2 * u)).n
    10
    >>> len(as_validation([(t, u, u), (t, u, 2 * u)])), as_validation(None) is None
    (2, True)
    """
    if validate is None or (isinstance(validate, list | tuple) and not validate):
        return None
    if isinstance(validate, list | tuple) and not all(np.ndim(v) == 1 for v in validate):
        runs = tuple(as_record(v) for v in validate)
        return runs if len(runs) > 1 else (runs[0] if runs else None)
    return as_record(validate)


def diagnose(plant: Plant, record: RecordLike, validate: RecordLike | Sequence[RecordLike] | None = None,
             candidates: list[str] | tuple[str, ...] | None = None, *, offset: str | float = "fit",
             train_fraction: float = 0.5, n_null: int = 19, n_boot: int = 1000, level: float = 0.95,
             seed: int = 0, split: str = "tail", burn_in: float = 0.0, max_effects: int = 2,
             workers: int = 1, heldout_offset: str = "auto", progress: dict[str, Any] | None = None) -> Diagnosis:
    """Localize the gap between ``plant`` and ``record`` and attribute it to one effect.

    Parameters
    ----------
    plant : Plant
        The nominal model, driven by the record's input (the measured command).
    record : Record, (t, u, y) arrays, N x 3 array, mapping of columns, DataFrame or path
        Measured command and output (aux channels become regime variables); anything
        :func:`synth.data.coerce.as_record` takes.
    validate : record-like or sequence of record-like, optional
        Held-out record for the shrinkage (several: runs of the same plant, each with its own
        offset, see :func:`synth.gap.attribution.heldout.diagnose_effects`); without it the record's second
        half is held out. Each in any form of ``record`` (see :func:`as_validation`).
    candidates : sequence of str, optional
        Effects to try (default: the default candidates of :mod:`synth.gap.effects`, and for each aux
        channel of the record the effects it may drive, :func:`synth.gap.effects.registry.aux_candidates`).
        An aux-driven effect (``measured_sag(Voltage)``) reads its channel from the record and the
        validation records.
    offset : "fit", "none" or float
        Output offset of the localization (the operating point the linear model does not know).
    train_fraction, n_null, n_boot, seed, split, burn_in, max_effects, workers, heldout_offset
        See :func:`synth.gap.attribution.heldout.diagnose_effects`.
    level : float
        Confidence level of the localization's tests.
    progress : dict, optional
        Filled as the diagnosis goes: ``"localization"`` (a :class:`GapLocalization`) once the gap is
        localized, ``"stage"`` the stage running (``"localization"``, ``"attribution"``, ``"done"``):
        what an interrupted run can still write; during the attribution ``"done"`` of ``"total"`` steps
        and ``"step"`` (see :func:`synth.gap.attribution.heldout.diagnose_effects`), for a progress bar.

    Returns
    -------
    Diagnosis

    Raises
    ------
    ModelError
        Unknown candidates, bad options; before any fitting, a model the record cannot judge
        (unstable, not simulable, a delay longer than the record: :func:`synth.gap.preflight.check_model`).
    DataError
        Input and output units of the validation record differ from the record's; an aux-driven
        candidate whose channel is missing; a record too short for a candidate.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 12, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(0.2*s+1)", delay=0.05), t, u)
    >>> y = y + 0.005 * np.random.default_rng(0).normal(size=t.size)
    >>> dg = diagnose(Plant.from_string("2/(0.2*s+1)"), record_from_arrays(t, u, y),
    ...               candidates=["delay", "lag"], n_null=3)
    >>> dg.verdict["effects"], round(dg.attribution.effects[0].parameters["delay"], 3)
    (['delay'], 0.05)
    >>> diagnose(Plant.from_string("2/(0.2*s+1)"), (t, u, y), candidates=["delay"], n_null=3).verdict["effects"]
    ['delay']
    """
    record = as_record(record)
    clips = record_clipping(record)  # an output clip seen in the data joins the default candidates
    default = list(dict.fromkeys([*DEFAULT_CANDIDATES, *aux_candidates(sorted(record.aux)),
                                  *(c.effect for c in clips if c.effect == "saturation(output)")]))
    names = check_candidates(list(default if candidates is None else candidates))
    validate = as_validation(validate)
    held_out = validate if isinstance(validate, tuple) else (() if validate is None else (validate,))
    effects = [make_effect(n).bind([record, *held_out], plant) for n in names]
    check_model(plant, record, effects, train_fraction if split == "tail" else 0.5, bool(held_out), split == "tail")
    progress = {} if progress is None else progress
    progress["stage"] = "localization"
    for i, v in enumerate(held_out):
        for side in ("input", "output"):
            a, b = getattr(record, side).unit, getattr(v, side).unit
            if a and b and a != b:
                where = "validate" if len(held_out) == 1 else f"validate run {i + 1}"
                raise DataError(f"{side} unit {b!r} differs from the record's {a!r}", where=where)
    loc = localize_gap(plant, record, offset=offset, level=level, burn_in=burn_in)
    progress.update(localization=loc, stage="attribution")
    att = diagnose_effects(plant, record, list(validate) if isinstance(validate, tuple) else validate,
                           options=DiagnoseOptions(candidates=effects, train_fraction=train_fraction, n_null=n_null,
                                                   n_boot=n_boot, seed=seed, split=split, burn_in=burn_in,
                                                   max_effects=max_effects, workers=workers, heldout_offset=heldout_offset),
                           progress=progress)
    att.verdict["not_carried"] = not_carried(att, DiagnoseOptions().confirm)
    channels = {e.label: e.aux_channel for e in effects if e.aux_channel}
    if channels:
        att.verdict["aux"] = aux_explained(att, channels)
    progress["stage"] = "done"
    warnings: list[str] = [] if held_out else heldout_warnings(record, None, split, train_fraction)
    warnings += [w for w in [start_transient_warning(plant, loc.residual)] if w]  # after any burn-in
    if loc.residual.left_out:
        warnings.append(not_judged_warning(loc.residual.left_out, loc.residual.dt, len(record.gaps), "the log"))
    warnings += hidden_pulse_warnings(record, loc.residual, plant)
    warnings += [w for w in [integrating_warning(plant, record)] if w]
    for i, v in enumerate(held_out):
        clips += record_clipping(v, "validate" if len(held_out) == 1 else f"validate {i + 1}")
        warnings += [w.replace("the validation record", f"validation run {i + 1}") if len(held_out) > 1 else w
                     for w in heldout_warnings(record, v)]
        judged = after_gaps(v, plant)
        if judged is not None and np.any(judged <= 0):
            label = "the validation record's log" if len(held_out) == 1 else f"validation run {i + 1}'s log"
            warnings.append(not_judged_warning(int(np.sum(judged <= 0)), 1.0 / v.fs, len(v.gaps), label))
    return Diagnosis(plant, record, validate, loc, att, tuple(clips), tuple(warnings))
