"""``synth hq``: handling-qualities bandwidth and phase delay of an attitude response."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

__all__ = ["COMMAND", "DESCRIPTION", "HELP", "ORDER", "add_arguments", "read_frd", "run"]

COMMAND = "hq"
ORDER = 40
HELP = "bandwidth and phase delay (seed 2, fig. 1) of a model or a measured frequency response"
DESCRIPTION = """Handling-qualities metrics of an attitude response (seed 2, sec. 6.2, fig. 1).

w180 (phase -180 deg), phase bandwidth (-135 deg), gain bandwidth (6 dB above the gain at w180),
the bandwidth by the response type's rule (rate: the lesser; attitude: the phase bandwidth) and
the phase delay tau_p = -(phi(2 w180) + 180 deg)/(2 w180). Measured data: a rough phase is read
through a least-squares line between w180 and 2 w180; the coherence gives each metric an
uncertainty.

--frd FILE is a CSV with columns w, mag_db, phase_deg[, coherence] (rad/s, dB, deg) or the JSON
of `synth freqresp` (keys w, magnitude_db, phase_deg, coherence, and the per-frequency averaging
count n_averages that freqresp records; a JSON key averages or --averages overrides it).

example:
  synth hq --tf "1/(s^2+s+1)" --delay 0.1
  synth hq --frd roll.csv --averages 20 --json hq.json --out reports/roll_hq
  synth hq --tf "1/(s^2+s+1)" --delay 0.1 --w1 20      # the report's example: tau_p at w1 = 20 rad/s

--w1 W also gives tau_p = -(phi(W) + 180 deg)/W (seed 2, eq. 2) at that frequency, beside the value at
2 w180 (values compare only at the same w1).

exit codes: 0 computed, 2 bad input"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--tf", help='attitude response model, e.g. "1/(s^2+s+1)"')
    src.add_argument("--frd", metavar="FILE", help="measured frequency response (CSV or synth freqresp JSON)")
    p.add_argument("--columns", metavar="OLD=NEW,...", action="append", default=[],
                   help="rename the --frd file's columns to w, mag_db, phase_deg, coherence, e.g. omega=w; "
                        "headers may carry units ('w (rad/s)')")
    p.add_argument("--delay", type=float, default=0.0, help="delay added to --tf [s]")
    p.add_argument("--response-type", choices=["auto", "rate", "attitude"], default="auto",
                   help="rate: bandwidth is the lesser of phase and gain bandwidths; attitude: the phase "
                        "bandwidth; auto (default): an integrator at low frequency means rate")
    p.add_argument("--all-points", action="store_true",
                   help="a synth freqresp JSON: use every frequency, not only its coherent band")
    p.add_argument("--averages", type=float, help="number of averages behind a measured response (uncertainty)")
    p.add_argument("--phase-fit", choices=["auto", "raw", "line"], default="auto",
                   help="measured data: how the phase at 2 w180 is read (default auto)")
    p.add_argument("--fit-band", nargs=2, type=float, metavar=("W1", "W2"),
                   help="band of the least-squares phase line [rad/s] (default w180 to 2 w180)")
    p.add_argument("--w1", type=float, metavar="W", help="also the phase delay at this frequency [rad/s] (seed 2, eq. 2)")
    p.add_argument("--json", metavar="FILE", help="write the metrics as JSON ('-' for standard output)")
    p.add_argument("--out", metavar="DIR", help="folder for hq.json and hq_bode.png")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")


def read_frd(path: str | Path, columns: dict[str, str] | None = None) -> dict[str, Any]:
    """Read a measured frequency response: ``synth freqresp`` JSON or CSV ``w, mag_db, phase_deg[, coherence]``.

    Returns ``{"w", "H", "coherence", "averages", "band"}`` (``H`` complex). ``averages`` is the JSON's
    ``averages`` (one number) or, in a ``synth freqresp`` result, its ``n_averages`` (one per
    frequency); ``None`` for a CSV. ``band``: the coherent band ``(w_min, w_max)`` a ``synth freqresp``
    result records, else ``None``. CSV headers may carry units (``w (rad/s)``, ``mag_db [dB]``);
    ``columns`` renames CSV columns first (``{"omega": "w"}``).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import numpy as np
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "f.csv"
    >>> _ = p.write_text("w,mag_db,phase_deg\\n1,0,-90\\n2,-6,-120\\n")
    >>> d = read_frd(p); np.abs(d["H"]).round(3).tolist(), np.angle(d["H"], deg=True).round(1).tolist()
    ([1.0, 0.501], [-90.0, -120.0])
    """
    import numpy as np

    from synth.data.readers import read_table
    from synth.errors import DataError

    path = Path(path)
    if path.suffix.lower() == ".json":
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise DataError(f"cannot read: {exc.strerror or exc}", where=str(path)) from None
        except ValueError as exc:
            raise DataError(f"not valid JSON: {exc}", where=str(path)) from None
        keys = {"w": "w", "mag_db": "magnitude_db", "phase_deg": "phase_deg", "coherence": "coherence"}
        averages, band = None, None
        if isinstance(data, dict):   # a number given by hand, else the per-frequency count synth freqresp records
            averages = data.get("averages", data.get("n_averages"))
            found = data.get("coherent_band")
            if isinstance(found, dict) and all(isinstance(found.get(k), (int, float)) for k in ("w_min", "w_max")):
                band = (float(found["w_min"]), float(found["w_max"]))
            elif isinstance(found, dict) and "w_min" in found and found.get("w_min") is None:
                band = ()  # freqresp found no coherent band
    else:
        table = read_table(path, columns)
        data = {}
        for name in ("w", "mag_db", "phase_deg", "coherence"):
            key = table.get(name)
            if key is None and name != "coherence":
                raise DataError(f"column '{name}' not found; found {', '.join(table.names()) or 'nothing'}",
                                where=str(path))
            if key is not None:
                data[name] = table.columns[table.find(key)] * _unit_factor(name, table.units.get(key, ""), path)
        keys = {"w": "w", "mag_db": "mag_db", "phase_deg": "phase_deg", "coherence": "coherence"}
        averages, band = None, None
    if not isinstance(data, dict):
        raise DataError("expected an object with w, magnitude_db, phase_deg", where=str(path))
    cols: dict[str, Any] = {}
    for role, key in keys.items():
        if key not in data or data[key] is None:
            if role == "coherence":
                cols[role] = None
                continue
            raise DataError(f"column '{key}' not found; found {', '.join(map(str, data)) or 'nothing'}",
                            where=str(path))
        try:
            cols[role] = np.asarray(data[key], float).ravel()
        except (TypeError, ValueError):
            raise DataError(f"column '{key}': values are not numbers", where=str(path)) from None
        bad = np.flatnonzero(~np.isfinite(cols[role]))
        if bad.size:
            raise DataError(f"column '{key}': {bad.size} value(s) are NaN or inf (first at row {bad[0]})",
                            where=str(path))
    sizes = {keys[r]: c.size for r, c in cols.items() if c is not None}
    if len(set(sizes.values())) > 1:
        raise DataError("columns differ in length: " + ", ".join(f"{k} {n}" for k, n in sizes.items()),
                        where=str(path))
    H = 10 ** (cols["mag_db"] / 20) * np.exp(1j * np.radians(cols["phase_deg"]))
    return {"w": cols["w"], "H": H, "coherence": cols["coherence"], "averages": averages, "band": band}


_UNITS = {"w": {"": 1.0, "rad/s": 1.0, "hz": 2.0 * math.pi, "1/s": 1.0},
          "mag_db": {"": 1.0, "db": 1.0},
          "phase_deg": {"": 1.0, "deg": 1.0, "degree": 1.0, "degrees": 1.0, "rad": 180.0 / math.pi},
          "coherence": {"": 1.0, "-": 1.0}}


def _unit_factor(name: str, unit: str, path: Path) -> float:
    """The factor from a CSV header's unit to the column's own (rad/s, dB, deg); an unknown unit is an error."""
    from synth.errors import DataError

    known = _UNITS[name]
    factor = known.get(unit.strip().lower())
    if factor is None:
        listed = ", ".join(k for k in known if k)
        raise DataError(f"column '{name}': unit '{unit}' is not one of {listed}", where=str(path))
    return factor


def within_band(frd: dict[str, Any], where: str) -> tuple[dict[str, Any], str | None]:
    """The response restricted to the coherent band it records (``read_frd``'s ``band``), and a note saying
    so; unchanged (and no note) without a band or when every point lies in it. Outside its band freqresp's
    estimate is leakage or noise whatever its coherence: a phase unwrapped from there put w180 at 0.11 rad/s
    and tau_p at 39 s for a loop whose w180 is 11.6 rad/s (a black-box test).

    Examples
    --------
    >>> import numpy as np
    >>> frd = {"w": np.array([0.1, 1.0, 2.0, 3.0, 50.0]), "H": np.ones(5, complex), "coherence": None,
    ...        "averages": [1, 2, 3, 4, 5], "band": (1.0, 3.0)}
    >>> kept, note = within_band(frd, "f.json"); kept["w"].tolist(), kept["averages"], note[:40]
    ([1.0, 2.0, 3.0], [2, 3, 4], 'used the coherent band 1-3 rad/s that fr')
    """
    import numpy as np

    from synth.errors import DataError

    band, w = frd.get("band"), frd["w"]
    if band is None:
        return frd, None
    if not band:
        raise DataError("freqresp found no coherent band in this response: no frequency of it is trusted "
                        "(--all-points uses every frequency, trusted or not)", where=where)
    keep = (w >= band[0] * (1 - 1e-9)) & (w <= band[1] * (1 + 1e-9))
    if keep.all():
        return frd, None
    if np.count_nonzero(keep) < 3:
        raise DataError(f"the coherent band {band[0]:.4g}-{band[1]:.4g} rad/s it records holds "
                        f"{np.count_nonzero(keep)} frequencies: too few for the metrics (--all-points uses every "
                        "frequency, trusted or not)", where=where)
    out = dict(frd)
    for key in ("w", "H", "coherence"):
        if out[key] is not None:
            out[key] = out[key][keep]
    averages = out["averages"]
    if isinstance(averages, list) and len(averages) == w.size:
        out["averages"] = [a for a, k in zip(averages, keep) if k]
    note = (f"used the coherent band {band[0]:.4g}-{band[1]:.4g} rad/s that freqresp recorded "
            f"({np.count_nonzero(keep)} of {w.size} frequencies): outside it the estimate is not trusted "
            "(--all-points uses every frequency)")
    return out, note


def _fmt(value: Any, unit: str, sigma: Any = None, digits: int = 4) -> str:
    if value is None:
        return "undefined"
    text = f"{value:.{digits}g} {unit}"
    return text + (f" +- {sigma:.2g}" if sigma is not None else "")


def _check_options(args: argparse.Namespace) -> None:
    """Options that belong to the other source, or a fit band that is no band: one line before any computation."""
    from synth.errors import SynthError

    if args.tf is not None:
        for flag, given in (("--averages", args.averages is not None), ("--phase-fit", args.phase_fit != "auto"),
                            ("--fit-band", args.fit_band is not None), ("--columns", bool(args.columns)),
                            ("--all-points", args.all_points)):
            if given:
                raise SynthError("applies to a measured response (--frd) only; a --tf model's response is exact",
                                 where=flag)
    elif args.delay != 0.0:
        raise SynthError("applies to --tf only: a measured response holds its delay already", where="--delay")
    if args.fit_band is not None:
        lo, hi = args.fit_band
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
            raise SynthError(f"expected two increasing frequencies > 0 rad/s, got {lo:g} {hi:g}", where="--fit-band")


def run(args: argparse.Namespace) -> int:
    from synth.cli._outputs import check_outputs
    from synth.cli._table import name_values
    from synth.data.readers import parse_column_map
    from synth.errors import DataError, ModelError
    from synth.ident.hq import hq_from_frd, hq_from_plant
    from synth.outputs import OutputDir, check_writable, dump_json, write_json
    from synth.plant import Plant

    check_outputs(args.out, ["hq.json", "hq_bode.png"], [args.json], args.force,
                  inputs=[args.frd])  # before any computation
    band_note = None
    _check_options(args)
    if args.tf is not None:
        try:
            plant = Plant.from_string(args.tf, delay=args.delay)
        except ModelError as exc:
            raise exc.located("--tf") from None
        m = hq_from_plant(plant, args.response_type)
        title = plant.to_string()
    else:
        frd = read_frd(args.frd, parse_column_map(args.columns))
        if not args.all_points:
            frd, band_note = within_band(frd, str(args.frd))
        averages = args.averages if args.averages is not None else frd["averages"]
        try:
            m = hq_from_frd(frd["w"], frd["H"], frd["coherence"], averages, args.response_type, args.phase_fit,
                            tuple(args.fit_band) if args.fit_band else None)
        except DataError as exc:
            if exc.where == "fit_band":
                raise DataError(exc.message, where="--fit-band") from None
            raise exc.located(args.frd) if exc.where == "frequency response" else exc from None
        title = str(args.frd)
    data = m.to_dict()
    if band_note is not None:
        data["notes"] = [band_note, *data.get("notes", [])]
        data["frequency_band_used"] = [float(m.w[0]), float(m.w[-1])]
    at_w1 = None
    if args.w1 is not None:  # phase delay at a stated w1 (issue 19): synth.ident.phase_delay
        from synth.ident.phase_delay import phase_delay_at

        at_w1 = phase_delay_at(m, args.w1, plant if args.tf is not None else None)
        data["phase_delay_at_w1"] = at_w1.to_dict()
    if args.json and args.json != "-":
        check_writable(Path(args.json), args.force)
    out = OutputDir(args.out, args.force) if args.out else None
    if out:
        write_json(out.claim("hq.json"), {**m.to_dict(curves=True), **data}, force=True)
        from synth.ident.hq_figures import hq_bode

        hq_bode(m, out.claim("hq_bode.png"), title)
        out.commit()
    if args.json == "-":
        sys.stdout.write(dump_json(data))
        return 0
    if args.json:
        write_json(args.json, data, force=args.force)
    u = m.uncertainty or {}
    lowest = "the coherent band's lowest frequency" if band_note else "the lowest frequency measured"
    below = f"below {m.w[0]:.4g} rad/s ({lowest})" if m.below_data else ""
    rows = [("w180", _fmt(m.w180, "rad/s", u.get("w180"))),
            ("bandwidth_phase (-135 deg)", below if "phase" in m.below_data
             else _fmt(m.bandwidth_phase, "rad/s", u.get("bandwidth_phase"))),
            ("bandwidth_gain (+6 dB)", below if "gain" in m.below_data
             else _fmt(m.bandwidth_gain, "rad/s", u.get("bandwidth_gain"))),
            ("bandwidth", below if m.bandwidth_limit == "below_data" else _fmt(m.bandwidth, "rad/s", u.get("bandwidth"))
             + (f"  ({m.bandwidth_limit}-limited)" if m.bandwidth else "")),
            ("phase delay tau_p", _fmt(m.phase_delay, "s", u.get("phase_delay"), 3)
             + (f"  (phase at 2 w180: {m.phase_2w180:.1f} deg, {m.phase_method})" if m.phase_2w180 is not None else ""))]
    print(f"{title}: {m.response_type} response type ({m.response_type_reason})")
    if at_w1 is not None:
        rows.append((f"phase delay at w1 = {at_w1.w1:g}", f"{at_w1.phase_delay:.3g} s  (phase {at_w1.phase_deg:.1f} deg "
                                                          f"at {at_w1.w1:g} rad/s, {at_w1.method})"))
    print(name_values(rows, ((band_note,) if band_note else ()) + tuple(m.notes)
                      + (tuple(at_w1.notes) if at_w1 is not None else ())))
    if out:
        print(f"wrote {out.path}/hq.json and {out.path}/hq_bode.png")
    return 0
