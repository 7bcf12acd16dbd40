"""``synth freqresp --data RUN.csv [--data RUN2.csv] --time t --input u --output y``: sweep identification."""

from __future__ import annotations

import argparse
import sys
from typing import Any

__all__ = ["COMMAND", "DESCRIPTION", "HELP", "ORDER", "add_arguments", "run"]

COMMAND = "freqresp"
ORDER = 40
HELP = "frequency response from sweep records (composite windows, coherence), transfer-function fit"
DESCRIPTION = """Identify a frequency response from one or several frequency-sweep runs.

The runs' segments are averaged together (the NASA report concatenates its best
2 of 3 runs); several window lengths are combined per frequency, weighted by
their random error. Prints the coherent band (coherence >= 0.8 and not
oscillating). --fit fits a transfer function with an exact delay over the band
(or --fit-range) minimizing J = (20/n) sum W_gamma [dB^2 + 0.01745 deg^2];
--verify simulates the fit on a separate step record.

example:
  synth freqresp --data run1.csv --data run2.csv --time t --input lat --output p \\
      --wmin 0.4 --wmax 12 --rate-to-attitude --fit "k*exp(-Td*s)/((s+p1)*(s+p2))" --out reports/roll
  synth freqresp --data sweep.csv --fit 0/2 --delay 0.02 --verify step.csv --json -

Quality: per run, the coherence share over the band, the input autospectrum's spread, the
output's symmetry about trim and (--off-axis) the off-axis share of the input power, ranked
with the runs to keep (the NASA report keeps the best 2 of 3). --divide-by removes known
sensor/filter dynamics, --skew a known lag of the output channel behind the input channel.

exit codes: 0 done, 1 no coherent band (the response and its figure are still written, to show
the coherence; hq refuses them without --all-points) or a failed fit (one line says what failed
and what to try; nothing written), 2 bad input"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--data", action="append", required=True, metavar="FILE",
                   help="sweep run (CSV or MAT); repeat for several runs")
    p.add_argument("--time", help="time column, with or without its unit (default: the first)")
    p.add_argument("--input", help="input column (default: the second)")
    p.add_argument("--output", help="output column (default: the third)")
    p.add_argument("--columns", metavar="OLD=NEW,...", action="append", default=[],
                   help="rename columns before picking them, e.g. acc[0]=accel_x (a MAT matrix gives acc[0], "
                        "acc[1], ...; a struct s.field); repeatable")
    p.add_argument("--dt", type=float, metavar="S", help="sample interval when the files have no time column")
    p.add_argument("--wmin", type=float, metavar="RAD_S", help="lowest frequency (default: what the runs support)")
    p.add_argument("--wmax", type=float, metavar="RAD_S",
                   help="highest frequency (default: a fifth of Nyquist; a note says how far above it the response "
                        "stays coherent, if it does)")
    p.add_argument("--windows", metavar="S,S,...", help="window lengths in s (default: 5, composite)")
    p.add_argument("--coherence", type=float, default=0.8, metavar="G2", help="coherence threshold (default 0.8)")
    p.add_argument("--points-per-decade", type=int, default=40, metavar="N",
                   help="density of the frequency grid (default 40; a lightly damped mode needs more)")
    p.add_argument("--divide-by", metavar="TF", help='known sensor/filter dynamics to remove, e.g. "50/(s+50)"')
    p.add_argument("--skew", type=float, default=0.0, metavar="S",
                   help="the output channel lags the input channel by S seconds (removed; default 0)")
    p.add_argument("--off-axis", metavar="COLUMN", help="off-axis control column: its share of the input power per run")
    p.add_argument("--rate-to-attitude", action="store_true", help="integrate the response by 1/s")
    p.add_argument("--fit", metavar="ORDERS|FORMULA", help='"0/2" or "k*exp(-Td*s)/((s+p1)*(s+p2))"')
    p.add_argument("--fit-range", metavar="LO:HI", help="fit range in rad/s (default: the coherent band)")
    p.add_argument("--delay", default="fit", metavar="fit|S", help="fit the delay (default) or hold it at S seconds")
    p.add_argument("--verify", metavar="FILE", help="step record (same columns) to verify the fit in time")
    p.add_argument("--json", metavar="FILE", help="write the result as JSON ('-' for standard output)")
    p.add_argument("--out", metavar="DIR", help="folder for result.json, bode.png and verify.png")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing; use the exit code")


def _floats(text: str, where: str, count: int | None = None, sep: str = ",") -> list[float]:
    from synth.errors import SynthError

    try:
        values = [float(x) for x in text.split(sep)]
    except ValueError:
        raise SynthError(f"expected numbers separated by '{sep}', got {text!r}", where=where) from None
    if (count is not None and len(values) != count) or not all(v > 0 for v in values):
        raise SynthError(f"expected {count or 'some'} positive number(s) separated by '{sep}', got {text!r}",
                         where=where)
    return values


def _load(path: str, args: argparse.Namespace, off_axis: bool = False) -> Any:
    from synth.data import load_record
    from synth.data.readers import parse_column_map

    aux = (args.off_axis,) if off_axis and args.off_axis else ()
    return load_record(path, args.time, args.input, args.output, aux=aux, dt=args.dt,
                       columns=parse_column_map(args.columns))


def _quality(runs: list[Any], resp: Any, args: argparse.Namespace) -> list[Any]:
    """Per-run quality figures over the coherent band (the whole grid if it has none, or one point), ranked."""
    from synth.ident.sweep_quality import rank_runs, run_quality

    band = (float(resp.w[0]), float(resp.w[-1]))
    if resp.band.found and resp.band.w_max > resp.band.w_min:
        band = (resp.band.w_min, resp.band.w_max)
    return rank_runs([run_quality(r, resp.w, band, resp.windows, args.off_axis, threshold=args.coherence)
                      for r in runs])


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    import numpy as np

    from synth.cli._outputs import check_outputs
    from synth.errors import ModelError, SynthError
    from synth.ident.freqfit import FrequencyFitError, fit_frequency_response
    from synth.ident.spectra import correct_response, frequency_response, rate_to_attitude
    from synth.ident.step_verification import verify_step
    from synth.outputs import OutputDir, dump_json, write_json
    from synth.plant import Plant

    check_outputs(args.out, ["result.json", "bode.png"], [args.json], args.force,
                  inputs=args.data)  # before any computation
    runs = [_load(p, args, off_axis=True) for p in args.data]
    if not 1 <= args.points_per_decade <= 2000:
        raise SynthError(f"must be between 1 and 2000, got {args.points_per_decade}", where="--points-per-decade")
    if not np.isfinite(args.skew):
        raise SynthError(f"must be a finite number of seconds, got {args.skew}", where="--skew")
    shortest = min(float(r.t[-1] - r.t[0]) for r in runs)
    if abs(args.skew) >= shortest:
        raise SynthError(f"a channel skew of {args.skew:g} s is not shorter than the shortest run ({shortest:.4g} s); "
                         "a skew is the lag of the output channel's clock, a few samples at most", where="--skew")
    sensor = None
    if args.divide_by:
        try:
            sensor = Plant.from_string(args.divide_by)
        except ModelError as exc:
            raise exc.located("--divide-by") from None
    windows = _floats(args.windows, "--windows") if args.windows else None
    for name in ("wmin", "wmax"):
        value = getattr(args, name)
        if value is not None and not value > 0:
            raise SynthError(f"must be a positive frequency in rad/s, got {value:g}", where=f"--{name}")
    if not 0 < args.coherence < 1:
        raise SynthError(f"must be between 0 and 1, got {args.coherence:g}", where="--coherence")
    delay: str | float = "fit"
    if args.delay != "fit":
        delay = _floats(args.delay, "--delay", 1)[0] if args.delay not in ("0", "0.0") else 0.0
    fit_range = tuple(_floats(args.fit_range, "--fit-range", 2, ":")) if args.fit_range else None
    if fit_range is not None and not args.fit:
        raise SynthError("nothing is fitted without --fit STRUCTURE (a black-box test's range was silently ignored)",
                         where="--fit-range")
    if fit_range is not None and not 0 < fit_range[0] < fit_range[1]:
        raise SynthError(f"must be LO:HI with 0 < LO < HI in rad/s, got {args.fit_range}", where="--fit-range")
    resp = frequency_response(runs, args.wmin, args.wmax, windows=windows, coherence_threshold=args.coherence,
                              points_per_decade=args.points_per_decade)
    if sensor is not None or args.skew:
        try:
            resp = correct_response(resp, sensor, args.skew)
        except SynthError as exc:
            raise exc.located("--divide-by") from None
    if args.rate_to_attitude:
        resp = rate_to_attitude(resp)
    quality = _quality(runs, resp, args)
    result: dict[str, Any] = {"kind": "frequency_response", **resp.to_dict(), "records": [r.to_dict() for r in runs],
                              "run_quality": [q.to_dict() for q in quality]}
    fit = verification = None
    if args.fit:
        if not resp.band.found and fit_range is None:
            raise SynthError("no coherent band to fit over; give --fit-range LO:HI", where="--fit")
        try:
            fit = fit_frequency_response(resp, args.fit, fit_range, delay)  # type: ignore[arg-type]
        except SynthError as exc:
            raise exc.located("--fit") from None
        except FrequencyFitError as exc:
            print(f"synth freqresp: error: --fit: {exc}", file=sys.stderr)
            return 1
        result["fit"] = fit.to_dict()
        if args.verify:
            verification = verify_step(fit.plant, _load(args.verify, args))
            result["verification"] = verification.to_dict()
    elif args.verify:
        raise SynthError("needs --fit (a model to verify)", where="--verify")
    if args.out:
        from synth.ident.freq_figures import bode_figure, verification_figure

        folder = OutputDir(args.out, args.force)
        json_path = folder.claim("result.json")
        bode_figure(resp, folder.claim("bode.png"), fit)
        result["figures"] = ["bode.png"]
        if verification is not None:
            verification_figure(verification, folder.claim("verify.png"), f"fit {fit.structure}")  # type: ignore[union-attr]
            result["figures"].append("verify.png")
        json_path.write_text(dump_json(result), encoding="utf-8")
        folder.commit()
    if args.json == "-":
        sys.stdout.write(dump_json(result))
    elif args.json:
        write_json(Path(args.json), result, force=args.force)
    if not args.quiet and args.json != "-":
        b = resp.band
        print(f"{resp.output} / {resp.input}: {len(runs)} run(s), windows "
              f"{', '.join(f'{x:.3g}' for x in resp.windows)} s, {resp.w.size} points "
              f"{resp.w[0]:.4g}-{resp.w[-1]:.4g} rad/s ({resp.kind})")
        print(f"coherent band (gamma^2 >= {b.threshold:g}, not oscillating): "
              + (f"{b.w_min:.4g}-{b.w_max:.4g} rad/s" if b.found else "none"))
        if b.note:
            print(f"note: {b.note}")
        for note in resp.notes:
            print(f"note: {note}")
        for note in resp.corrections:
            print(f"correction: {note}")
        if len(quality) == 1 and not args.off_axis and "warning" in quality[0].reason:
            print(f"run quality: {quality[0].reason} (input spread {quality[0].input_db_spread:.1f} dB; an "
                  "under-excited frequency's response may be leakage from the others, coherence or not)")
        if len(quality) > 1 or args.off_axis:
            print("runs, best first (" + ("keep " + ", ".join(q.source for q in quality if q.keep)) + "):")
            for q in quality:
                off = f", off-axis {100 * q.off_axis_share:.0f} %" if q.off_axis_share is not None else ""
                print(f"  {q.rank}. {q.source}{'' if q.keep else ' (drop)'}: {q.reason}; input spread "
                      f"{q.input_db_spread:.1f} dB, output asymmetry {q.output_asymmetry:+.2f}{off}")
        if fit is not None:
            print(f"fit {fit.structure} over {fit.w_range[0]:.4g}-{fit.w_range[1]:.4g} rad/s: {fit.tf_text()}")
            sd = fit.uncertainty.std if fit.uncertainty is not None else {}
            print("  " + ", ".join(f"{k} = {v:.6g}" + (f" +- {sd[k]:.3g}" if k in sd else "")
                                   for k, v in fit.parameters.items()) + f"; J = {fit.J:.4g}")
            for line in fit.uncertainty.lines() if fit.uncertainty is not None else []:
                print("  " + line)
            for note in fit.notes:
                print(f"  warning: {note}")
        if verification is not None:
            print(f"step verification ({verification.source}): fit {verification.fit_percent:.1f} %, "
                  f"NRMSE {verification.nrmse:.4f}")
        if args.out:
            print(f"wrote {args.out}/result.json, " + ", ".join(f"{args.out}/{f}" for f in result["figures"]))
    return 0 if resp.band.found else 1
