"""``synth identify --data FILE ... --structure FORMULA``: fit a plant structure to a measured record."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

__all__ = ["COMMAND", "DESCRIPTION", "HELP", "ORDER", "add_arguments", "run"]

COMMAND = "identify"
ORDER = 5
HELP = "identify a plant structure from a step train or any input/output record"
DESCRIPTION = """Identify a parametric plant from a measured record (CSV or MAT).

A two-level input with several steps is a step train: the steps are found,
aligned and averaged (SNR before and after is printed), then the structure is
fitted to the average by simulation error (casadi + IPOPT; records over 10,000
samples by FFT convolution and Levenberg-Marquardt) with an optional delay and
an optional known sensor in series (the fit is F*H; F is reported). A train
whose model does not settle between steps, or that starts from rest, is fitted
on the whole record. Any other record is fitted as it is. Prints each parameter
with its standard error and 95 % interval and the fit percent, and marks a
parameter the record cannot pin down as weak (its correlation partner and
interval; also in the JSON, "weakly_identifiable"), and a parameter correlated 0.9 or more with a weak
one as tied to it ("tied_to_weak"); writes identify.json, fit.png
(data, model, residuals) and train.png into --out (default
reports/identify/<data file stem>/). Files synth did not write are never
overwritten (use --force).

example:
  synth identify --x4-demo
  synth identify --data run.csv --time t --input pwm --output speed \\
      --structure "k*(s+z)/((s+p1)*(s+p2))" --delay fit --sensor "442/((s+45)*(s+9.7))"
  synth identify --data 06_dc_step_5_15_00.mat --time Zeit --input Motorspannung \\
      --output Geschwindigkeit --structure "K/(T1*s+1)^2" --delay fit --json dc.json
  synth identify --data stand.csv --time "Time (s)" --input "ESC signal" --output Thrust \\
      --structure "K/(T*s+1)" --delay fit
  synth identify --data runs.mat --columns "data[0]=t,data[4]=torque,data[3]=speed" \\
      --time t --input torque --output speed --structure "K/(T*s+1)"

Up and down steps of a train are also fitted apart and compared parameter by parameter
against their standard errors; a difference beyond them is reported (with its size in
standard errors and its p-value). --by-direction reports both fits as the model.

--split-check PARTS cuts the record into PARTS contiguous parts, identifies each as the whole
and tests whether the part estimates scatter as their own stds say (chi-square over the parts);
"stds too small" names the factor by which they scatter more (coloured noise, a drift, dynamics
that change over the record). Also in the JSON, "split_check".

Records: '#' comment lines anywhere; units in headers ('Time (s)', 'Voltage [V]') become the
signals' units and columns may be named with or without them; uneven time stamps are resampled
with the input held between samples (a step stays a step) and the output interpolated.

--x4-demo uses a SYNTHETIC X-4 step train generated from the seed paper's model
(not measured data; see synth.ident.x4_record).

A fit that fails (IPOPT diverged, or hit its iteration limit more than 0.1 standard errors from
the optimum, parameters at absurd magnitudes, a fitted delay outside the record, a fit no better
than the output's mean or than noise) is never written as a result: one line says what failed and
what to try, exit 1. A fit stopped at its limit closer than that has converged as far as the record
can tell; the status line says how close.

exit codes: 0 identified, 1 the fit failed, 2 bad input"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--data", metavar="FILE", help="record: CSV with a header row, or MAT")
    p.add_argument("--time", metavar="COL", help="time column, with or without its unit (default: the first)")
    p.add_argument("--input", metavar="COL", help="input column (the command; default: the second)")
    p.add_argument("--output", metavar="COL", help="output column (default: the third)")
    p.add_argument("--dt", type=float, metavar="S",
                   help="sample interval when the file has no time column (input and output default to the first "
                        "two columns)")
    p.add_argument("--columns", metavar="OLD=NEW,...", action="append", default=[],
                   help="rename columns before picking them, e.g. acc[0]=accel_x (a MAT matrix gives acc[0], "
                        "acc[1], ...; a struct s.field); repeatable")
    p.add_argument("--input-unit", default="", metavar="UNIT",
                   help="unit of the input, e.g. PWM or V (default: the header's, as in 'pwm (us)')")
    p.add_argument("--output-unit", default="", metavar="UNIT",
                   help="unit of the output, e.g. rad/s (default: the header's)")
    p.add_argument("--structure", metavar="FORMULA",
                   help='plant structure; names other than s are parameters, e.g. "k*(s+z)/((s+p1)*(s+p2))"')
    p.add_argument("--delay", metavar="fit|SECONDS",
                   help="fit the delay or fix it (default: the formula's exp(-Td*s), else none)")
    p.add_argument("--sensor", metavar="TF", help='known sensor in series, e.g. "442/((s+45)*(s+9.7))"')
    p.add_argument("--average", choices=["auto", "cycle", "edge", "none"], default="auto",
                   help="step-train averaging (default auto: average a two-level input with several steps)")
    p.add_argument("--by-direction", action="store_true",
                   help="direction-dependent model: fit the up steps and the down steps apart and report both "
                        "(a step train is always checked for a difference between them)")
    p.add_argument("--split-check", type=int, default=0, metavar="PARTS",
                   help="also cut the record into PARTS (3 or more) contiguous parts, identify each and test whether "
                        "their estimates scatter as their stds say (coloured noise, drift or changing dynamics make "
                        "the stds too small); costs PARTS more fits")
    p.add_argument("--x4-demo", action="store_true",
                   help="use the SYNTHETIC X-4 step train (generated on first use) with the paper's structure and sensor")
    p.add_argument("--out", metavar="DIR", help="folder for identify.json and figures "
                   "(default reports/identify/<data file stem>)")
    p.add_argument("--json", metavar="FILE", help="also write the JSON to FILE ('-' for standard output)")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing; use the exit code")


def _demo_defaults(args: argparse.Namespace) -> None:
    from synth.ident import x4_record as x4

    args.data = args.data or str(x4.x4_step_train_path())
    args.time = args.time or x4.COLUMNS[0]
    args.input = args.input or x4.COLUMNS[1]
    args.output = args.output or x4.COLUMNS[2]
    args.input_unit = args.input_unit or "PWM"
    args.output_unit = args.output_unit or "rad/s"
    args.structure = args.structure or x4.STRUCTURE
    args.sensor = args.sensor or x4.SENSOR
    args.delay = args.delay or "fit"


def run(args: argparse.Namespace) -> int:
    from synth.data import load_record
    from synth.data.readers import parse_column_map
    from synth.errors import FitError, ModelError, SynthError
    from synth.ident.identification import identify
    from synth.ident.structure import parse_structure
    from synth.outputs import OutputDir, dump_json, write_json

    if args.x4_demo:
        _demo_defaults(args)
    if not args.data:
        raise SynthError("give the record, e.g. --data run.csv (or --x4-demo)", where="--data")
    if not args.structure:
        raise SynthError('give the plant structure, e.g. --structure "k/(s+p)"', where="--structure")
    if args.split_check and args.split_check < 3:
        raise SynthError(f"needs 3 parts or more, got {args.split_check}", where="--split-check")
    from synth.cli._outputs import check_outputs

    check_outputs(Path(args.out) if args.out else Path("reports") / "identify" / Path(args.data).stem,
                  ["identify.json"] + ([] if args.no_figures else ["fit.png", "train.png"]), [args.json], args.force,
                  inputs=[args.data])
    try:
        structure = parse_structure(args.structure)
    except ModelError as exc:
        raise exc.located("--structure") from None
    record = load_record(args.data, args.time, args.input, args.output, input_unit=args.input_unit,
                         output_unit=args.output_unit, dt=args.dt, columns=parse_column_map(args.columns))
    try:
        result = identify(record, structure, args.delay, args.sensor, args.average, by_direction=args.by_direction)
    except FitError as exc:  # the options were valid; the structure does not fit this record
        print(f"synth identify: {exc}", file=sys.stderr)
        return 1
    except ModelError as exc:
        where = "--delay" if "delay" in exc.message and "structure" not in exc.message else None
        raise (exc.located(where) if where else exc) from None
    units = _units(result)
    payload: dict[str, Any] = {"data": str(args.data), **result.to_dict(), "parameter_units": units}
    if args.split_check:
        from synth.errors import DataError
        from synth.ident.split_check import split_check

        try:
            check = split_check(record, structure, args.delay, args.sensor, args.average, parts=args.split_check,
                                reference={**result.fit.parameters})
        except DataError as exc:
            raise SynthError(exc.message, where="--split-check") from None
        payload["split_check"] = check.to_dict()
    if args.x4_demo:
        payload["synthetic"] = "SYNTHETIC record generated from the seed paper's model (synth.ident.x4_record)"
    out_dir = Path(args.out) if args.out else Path("reports") / "identify" / Path(args.data).stem
    folder = OutputDir(out_dir, args.force)
    json_path = folder.claim("identify.json")
    figures: list[Path] = []
    if not args.no_figures:
        from synth.ident.step_figures import fit_figure, train_figure

        figures.append(fit_figure(result.fit, folder.claim("fit.png")))
        figures.append(train_figure(record, folder.claim("train.png")))
    json_path.write_text(dump_json(payload), encoding="utf-8")
    folder.commit()
    json_path, figures = folder.final(json_path), [folder.final(f) for f in figures]  # the paths after the move
    if args.json == "-":
        sys.stdout.write(dump_json(payload))
    elif args.json:
        write_json(args.json, payload, force=args.force)
    if not args.quiet and args.json != "-":
        _print(result, units, args, json_path, figures)
        if "split_check" in payload:
            print(payload["split_check"]["text"])
    return 0


def _units(result: Any) -> dict[str, str]:
    """Each fitted parameter's unit (synth.ident.parameter_units), the delay's and the offset's too."""
    from synth.ident.parameter_units import parameter_units

    fit = result.fit
    units = parameter_units(fit.structure, fit.plant.input.unit, fit.plant.output.unit)
    delay = fit.structure.delay if isinstance(fit.structure.delay, str) else "delay"
    return {**units, delay: "s", "offset": fit.plant.output.unit or "output"}


def _print(result: Any, units: dict[str, str], args: argparse.Namespace, json_path: Path, figures: list[Path]) -> None:
    from synth.cli._table import table

    fit = result.fit
    rows = []
    for name, value in fit.parameters.items():
        lo, hi = fit.ci95[name]
        fixed = name not in fit.names
        rows.append([name, f"{value:.6g}", "fixed" if fixed else f"{fit.std[name]:.3g}",
                     "-" if fixed else f"[{lo:.6g}, {hi:.6g}]", units.get(name, "?") or "-"])
    rows.append(["offset", f"{fit.offset:.6g}", f"{fit.offset_std:.3g}", "", units["offset"]])
    print(f"{args.data}{' (SYNTHETIC)' if args.x4_demo else ''}: {fit.structure.formula}"
          f"{', sensor ' + fit.sensor.to_string() if fit.sensor is not None else ''}")
    for note in result.record.notes:  # how the record was read (resampled, converted, gaps): what the fit rests on
        print(f"note: {note}")
    avg = result.average
    if avg is not None:
        print(f"averaged {avg.count} {avg.mode}s ({avg.up} up, {avg.down} down steps, {avg.dropped} dropped"
              f"{f', {avg.in_gaps} of them holding a gap in the log' if avg.in_gaps else ''}): "
              f"SNR {avg.snr_before_db:.1f} dB -> {avg.snr_after_db:.1f} dB "
              f"(noise std {avg.noise_std_before:.3g} -> {avg.noise_std_after:.3g}, step {avg.step_size:.4g})")
    if result.whole_record_note:
        print(result.whole_record_note)
    weak, tied = fit.weak, fit.tied
    for row in rows:
        if any(w.name == row[0] for w in weak):
            row[0] += " (weak)"
        elif any(t.name == row[0] for t in tied):
            row[0] += " (tied to weak)"
    print(table(["parameter", "value", "std", "95 % interval", "unit"], rows))
    for w in weak:
        print(w.text() + ": the record cannot pin it down; do not use it as a confident number")
    for t in tied:
        print(t.text())
    for step in fit.solver.get("pair_profile", []):
        if step.get("note"):
            print(f"note: {step['note']}")
    if fit.solver.get("covariance_note"):
        print(f"note on the std column: {fit.solver['covariance_note']}")
    for key in ("nyquist_note", "zero_delay"):
        if fit.solver.get(key):
            print(f"note: {fit.solver[key]}")
    solver = "Levenberg-Marquardt" if fit.solver.get("method", "").startswith("Levenberg-Marquardt") else "IPOPT"
    status, iterations = fit.solver.get("status"), fit.solver.get("iterations")
    remaining = fit.solver.get("remaining_improvement_std")
    at_limit = (f"; stopped at its limit within {max(remaining, 0.01):.2g} standard errors of the optimum, converged "
                "as far as the record can tell" if remaining is not None and math.isfinite(remaining) else "")
    ending = (f"the start kept ({solver} ended above it after {iterations} iterations)" if status == "Start_Converged"
              else f"{solver} {status} ({iterations} iterations{at_limit})")
    print(f"fit {fit.fit_percent:.2f} %, residual std {fit.residual_std:.3g}, {ending}")
    print(f"plant: {fit.plant.to_string()}")
    if result.directions is not None:
        comp = result.directions
        if result.by_direction:
            for label, side in (("up steps", comp.up), ("down steps", comp.down)):
                print(f"\n{label}: {side.plant.to_string()} (fit {side.fit_percent:.2f} %)")
                print(table(["parameter", "value", "std", "up - down", "sigma"],
                            [[k, f"{v:.6g}", f"{side.std[k]:.3g}", f"{comp.difference[k]:+.3g}" if k in comp.z else "",
                              f"{comp.z[k]:+.1f}" if k in comp.z else ""] for k, v in side.parameters.items()]))
        hint = " (--by-direction reports both fits)" if comp.significant and not result.by_direction else ""
        print(comp.summary() + hint)
    elif result.direction_note:
        print(result.direction_note)
    print(f"\nresult: {json_path}" + "".join(f"\nfigure: {p}" for p in figures))
