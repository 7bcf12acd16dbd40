"""``synth psd``: spectrum of measured disturbance records (seed 1, section 5)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

__all__ = ["COMMAND", "DESCRIPTION", "HELP", "ORDER", "add_arguments", "run"]

COMMAND = "psd"
ORDER = 45
HELP = "disturbance spectrum: Welch PSD, trend, noise floor, spikes, bandwidth from the power share"
DESCRIPTION = """Power spectral density of one or several disturbance records (seed 1, sec. 5).

One-sided Welch PSD in unit^2/(rad/s) on rad/s (records averaged), its log-log trend (dB/decade),
the noise floor, narrow-band spikes, and the frequency below which --share of the disturbance
power above the floor lies. The suggested bandwidth requirement is --factor times that frequency:
feedback attenuates a disturbance only below the loop's bandwidth. No requirement is suggested when the
power above the floor is within the Welch estimate's chi-square scatter (false-alarm rate 0.1 %), and it is
"undetermined" with fewer than 4 segments averaged. Bands must lie in (0, Nyquist]; uneven time stamps
that jitter around a grid are used without interpolation (otherwise the note states the interpolation's
attenuation), a record is split at gaps of 5 intervals or more (its pieces averaged), a suggestion that
tones interpolated across dropped stamps could explain is withheld, and the variance printed is the raw
samples'.

example:
  synth psd --data env.csv --data env2.csv --time t --signal speed --unit rad/s
  synth psd --data hover.mat --time t --signal speed --noise-data stopped.mat --share 0.9 --out reports/psd
  synth psd --data hover.csv --time t --signal speed --noise-data stopped.csv --requirements --resolution 1.2 \
            --out reports/disturbance

--requirements (implied by --resolution) derives the sensitivity level, its band and the bandwidth
floor from the disturbance (synth.ident.disturbance_requirements): the level brings the spectrum's
plateau down to the sensor floor (the noise record's level, or the resolution's quantization noise,
whichever is larger), the band ends at the plateau's corner, the bandwidth floor is where the
disturbance falls to --margin-db above the sensor floor. It prints the ready `requirements:` block and
its evidence; with --out it also writes requirements.yaml and disturbance_requirements.png.

exit codes: 0 computed, 2 bad input"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--data", action="append", required=True, metavar="FILE",
                   help="CSV or MAT record (repeat for several; same sample rate)")
    p.add_argument("--time", help="time column [s], with or without its unit (omit with --dt)")
    p.add_argument("--signal", required=True, help="disturbance column")
    p.add_argument("--columns", metavar="OLD=NEW,...", action="append", default=[],
                   help="rename columns before picking them, e.g. acc[0]=accel_x (a MAT matrix gives acc[0], "
                        "acc[1], ...; a struct s.field); repeatable")
    p.add_argument("--unit", default="", help="unit of the signal (labels; default: the header's)")
    p.add_argument("--dt", type=float,
                   help="sample interval [s] for files without a time column (with --time: must agree within 1 %%)")
    p.add_argument("--noise-data", action="append", default=[], metavar="FILE",
                   help="noise-only record (e.g. motor stopped) whose level is the noise floor")
    p.add_argument("--share", type=float, default=0.9, help="share of disturbance power (default 0.9)")
    p.add_argument("--factor", type=float, default=1.0, help="bandwidth = factor x share frequency (default 1)")
    p.add_argument("--band", nargs=2, type=float, metavar=("W1", "W2"), help="trend band [rad/s]")
    p.add_argument("--floor-band", nargs=2, type=float, metavar=("W1", "W2"),
                   help="band where the spectrum is flat noise [rad/s] (default: upper half)")
    p.add_argument("--w-min", type=float, help="lowest frequency of interest [rad/s] (sets the segment length)")
    p.add_argument("--segment", type=float, help="Welch segment length [s]")
    p.add_argument("--spike-db", type=float, default=10.0, help="spike threshold above the running median [dB]")
    p.add_argument("--detrend", choices=["constant", "linear"], default="constant",
                   help="removed from each segment (linear for battery drift)")
    req = p.add_argument_group("requirements from the disturbance (issue 19)")
    req.add_argument("--requirements", action="store_true",
                     help="derive the sensitivity level and band and the bandwidth floor; print the requirements block")
    req.add_argument("--resolution", type=float, metavar="Q",
                     help="sensor resolution in signal units: its quantization noise joins the sensor floor "
                          "(implies --requirements)")
    req.add_argument("--margin-db", type=float, metavar="DB",
                     help="bandwidth floor: where the disturbance falls to this far above the sensor floor (default 3)")
    p.add_argument("--json", metavar="FILE", help="write the analysis as JSON ('-' for standard output)")
    p.add_argument("--out", metavar="DIR", help="folder for psd.json and psd.png")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")


def run(args: argparse.Namespace) -> int:
    from synth.cli._outputs import check_outputs
    from synth.cli._table import name_values
    from synth.data.readers import parse_column_map
    from synth.errors import DataError, SynthError
    from synth.ident.bandwidth_suggestion import suggest_bandwidth
    from synth.ident.psd import MIN_SEGMENTS, analyze_records
    from synth.ident.psd_stamps import load_psd_records
    from synth.ident.welch import unit_squared
    from synth.outputs import OutputDir, check_writable, dump_json, write_json

    check_outputs(args.out, ["psd.json", "psd.png"], [args.json], args.force,
                  inputs=args.data)  # before any computation
    _check_options(args)
    columns = parse_column_map(args.columns)
    loaded = [piece for f in args.data for piece in load_psd_records(f, args.time, args.signal, args.unit, args.dt,
                                                                         columns)]
    records = [r for r, _ in loaded]
    noise = [r for f in args.noise_data for r, _ in load_psd_records(f, args.time, args.signal, args.unit, args.dt,
                                                                     columns)]
    _check_against_records(args, [*records, *noise])
    raw_var = sum(ms * r.x.size for r, ms in loaded) / sum(r.x.size for r in records)
    a = analyze_records(records, noise, share=args.share, band=tuple(args.band) if args.band else None,
                        segment=args.segment, w_min=args.w_min,
                        floor_band=tuple(args.floor_band) if args.floor_band else None, spike_db=args.spike_db,
                        detrend=args.detrend)
    suggestion = None
    if a.share_frequency is not None and a.suggestion_withheld is None:
        try:
            suggestion = suggest_bandwidth(a, args.factor)
        except DataError as exc:  # a factor whose bandwidth is not finite
            raise SynthError(exc.message, where="--factor") from None
    withheld = a.suggestion_withheld or "none: no disturbance power above the noise floor"
    data = {**a.to_dict(), "raw_variance": raw_var, "records": [r.to_dict() for r in records],
            "noise_records": [r.to_dict() for r in noise],
            "bandwidth_suggestion": suggestion.to_dict() if suggestion else
            {"status": withheld.split(":")[0], "reason": withheld}}
    undetermined = a.suggestion_withheld if a.segments < MIN_SEGMENTS else None
    derived = _derive_requirements(args, a, records[0].dt) if undetermined is None else None
    if derived is not None:
        data["requirements"] = derived.to_dict()
    elif undetermined is not None and (args.requirements or args.resolution is not None):
        data["requirements"] = {"status": "undetermined", "reason": undetermined}
    if args.json and args.json != "-":
        check_writable(Path(args.json), args.force)
    out = OutputDir(args.out, args.force) if args.out else None
    if out:
        write_json(out.claim("psd.json"), {**data, "curves": a.to_dict(curves=True)["curves"]}, force=True)
        from synth.ident.psd_figures import psd_plot

        psd_plot(a, out.claim("psd.png"), f"{args.signal}: " + ", ".join(Path(f).name for f in args.data))
        if derived is not None:
            from synth.ident.disturbance_requirements_figure import disturbance_requirements_plot

            out.claim("requirements.yaml").write_text(derived.yaml() + "\n", encoding="utf-8")
            disturbance_requirements_plot(a, derived, out.claim("disturbance_requirements.png"),
                                          f"{args.signal}: requirements from the disturbance")
        out.commit()
    if args.json == "-":
        sys.stdout.write(dump_json(data))
        return 0
    if args.json:
        write_json(args.json, data, force=args.force)
    unit = args.unit or records[0].unit  # the header's unit when none is given
    u, u2 = unit or "unit", unit_squared(unit)
    print(f"{args.signal} [{u}]: {len(records)} record(s), {a.segments} Welch segments of {a.segment_length:.4g} s, "
          f"resolution {a.resolution:.3g} rad/s")
    rows = [("noise floor", f"{a.floor_db:.1f} dB re 1 {u2}/(rad/s) ({a.floor_source}, "
                            f"{a.floor_band[0]:.4g}-{a.floor_band[1]:.4g} rad/s)"),
            ("trend", f"{a.trend.slope_db_per_decade:+.1f} dB/decade over {a.trend.band[0]:.3g}-{a.trend.band[1]:.3g} "
                      f"rad/s (rms {a.trend.rms_residual_db:.1f} dB)" if a.trend else "none"),
            ("spikes", ", ".join(f"{s.w:.1f} rad/s (+{s.height_db:.0f} dB, amplitude {s.amplitude:.3g} {u})"
                                 for s in a.spikes[:8]) + (" ..." if len(a.spikes) > 8 else "") or "none"),
            (f"{100 * a.share:g} % of disturbance power below",
             f"{a.share_frequency:.4g} rad/s (spikes counted: {a.share_frequency_with_spikes:.4g} rad/s)"
             if a.share_frequency is not None else "undefined" + (
                 f" (spikes counted: {a.share_frequency_with_spikes:.4g} rad/s)"
                 if a.share_frequency_with_spikes is not None else "")),
            ("variance", f"{raw_var:.4g} {u2}, mean square about the mean of the raw samples (the spectrum "
                         f"integrates to {a.total_power:.4g} "
                            f"{u2}; above the floor: {a.disturbance_power:.4g} {u2}, scatter "
                            f"{a.disturbance_power_scatter:.2g} {u2})")]
    if suggestion:
        rows.append(("suggested requirement", f"{suggestion.spec_entry()}  (bandwidth >= {suggestion.factor:g} x "
                                              f"{suggestion.share_frequency:.4g} rad/s)"))
    else:
        rows.append(("suggested requirement", withheld))
    print(name_values(rows, a.notes))
    if undetermined is not None and (args.requirements or args.resolution is not None):
        print(f"\nrequirements from the disturbance: {undetermined}")
    if derived is not None:
        print("\nrequirements from the disturbance:\n" + derived.yaml())
        print(name_values([(e.name, f"{e.value:.4g} {e.unit}  ({e.feature})") for e in derived.evidence],
                          derived.notes))
    if out:
        extra = ", requirements.yaml and disturbance_requirements.png" if derived is not None else ""
        print(f"wrote {out.path}/psd.json, {out.path}/psd.png{extra}")
    return 0


def _derive_requirements(args: argparse.Namespace, analysis: Any, dt: float) -> Any:
    """The requirements block from the disturbance when --requirements or --resolution asks for it, else None."""
    if not (args.requirements or args.resolution is not None):
        if args.margin_db is not None:
            from synth.errors import SynthError

            raise SynthError("used only with --requirements (or --resolution)", where="--margin-db")
        return None
    from synth.errors import DataError
    from synth.ident.disturbance_requirements import requirements_from_disturbance
    from synth.ident.psd import KNEE_DB

    try:
        return requirements_from_disturbance(analysis, args.resolution, dt,
                                             KNEE_DB if args.margin_db is None else args.margin_db)
    except DataError as exc:
        flag = "--resolution" if "resolution" in exc.message else "--margin-db" if "margin" in exc.message else None
        raise exc.located(flag) if flag else exc from None


def _check_options(args: argparse.Namespace) -> None:
    """Refuse bad option values before any file is read (one line naming the option)."""
    from synth.errors import SynthError

    for flag, value, what in (("--factor", args.factor, "a finite number > 0"),
                              ("--spike-db", args.spike_db, "a finite number of dB > 0"),
                              ("--dt", args.dt, "a finite number > 0 s"),
                              ("--segment", args.segment, "a finite number > 0 s"),
                              ("--w-min", args.w_min, "a finite number > 0 rad/s")):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise SynthError(f"must be {what}, got {value:g}", where=flag)
    if args.time is not None and args.time == args.signal:
        raise SynthError(f"names the time column '{args.time}' (--time); give the disturbance's own column",
                         where="--signal")
    if not (math.isfinite(args.share) and 0 < args.share < 1):
        raise SynthError(f"share must lie strictly between 0 and 1, got {args.share:g}", where="--share")


def _check_against_records(args: argparse.Namespace, records: list[Any]) -> None:
    """Check --dt against the time column and the bands against the Nyquist frequency of the records."""
    from synth.errors import SynthError
    from synth.ident.psd import check_band

    dt = records[0].dt
    units = {r.unit: r.source for r in records if r.unit}
    if len(units) > 1:  # spectra in different units cannot be averaged or compared
        (u1, f1), (u2, f2) = list(units.items())[:2]
        raise SynthError(f"{f2}: the signal '{args.signal}' is in {u2}, in {f1} it is in {u1}; give every record "
                         "(and --noise-data) in one unit", where="--noise-data" if f2 in args.noise_data else "--data")
    if args.dt is not None and args.time is not None:
        for r in records:
            if abs(args.dt - r.dt) > 0.01 * r.dt:
                raise SynthError(f"{args.dt:g} s disagrees with the {r.dt:.4g} s of the time column '{args.time}' in "
                                 f"{r.source} (by more than 1 %); leave out --dt or --time", where="--dt")
    for flag, band in (("--band", args.band), ("--floor-band", args.floor_band)):
        if band is not None:
            check_band(band, dt, flag)
