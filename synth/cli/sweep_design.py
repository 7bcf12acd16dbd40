"""``synth sweep-design``: a frequency-sweep input for the rig, as the NASA sweep report recommends (seed 2)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

__all__ = ["COMMAND", "DESCRIPTION", "HELP", "ORDER", "SHORT_SWEEP", "add_arguments", "run", "sweep_csv_text"]

MAX_SAMPLES = 20_000_000
"""Most samples one run's CSV may hold (about 0.5 GB of text)."""

COMMAND = "sweep-design"
ORDER = 38
HELP = "design a frequency-sweep test input (seed 2): range, duration, amplitude, fades; a CSV for the rig"
DESCRIPTION = """Plan one frequency-sweep run and write its input as a CSV for the rig (seed 2, sec. 2 and 6.1).

The recipe (synth.ident.sweep_design.design_sweep): the lowest frequency sets the longest period
T_max = 2 pi / w_min; each run starts at trim with two cycles of T_max, then raises the frequency
gradually (exponential sweep) up to w_max and returns to trim; a run lasts 90 s or 4.5 T_max, whichever
is longer; 3 runs are flown and the best 2 concatenated. The input fades in over --fade seconds (raised
cosine; default T_max / 4) so the rig starts at trim, and fades out the same way at the end. The whole
band w_min-w_max is swept at full amplitude: the fade-out starts when the sweep reaches w_max and carries
it on above (to the "fade-out" frequency printed), for at least the time the sweep needs to pass w_max
cleanly, so the top of the band is excited as well as the rest; the run ends at trim. Time is in s, the
input in the rig's units (--amplitude is the peak).

The CSV has a first line naming synth (so re-running replaces it), then columns time_s and --name.
An existing file that synth did not write is never replaced (--force to do so).

example:
  synth sweep-design --w-min 0.4 --w-max 12 --amplitude 1.5 --out roll_sweep.csv
  synth sweep-design --w-min 1 --w-max 300 --duration 120 --amplitude 20 --sample-rate 1000 --out rotor_sweep.csv

exit codes: 0 written, 2 bad input"""


SHORT_SWEEP = 0.25
"""A sweep (the run after its two low-frequency cycles) shorter than this share of the recipe's gets a warning."""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--w-min", type=float, required=True, metavar="W", help="lowest frequency of interest [rad/s]")
    p.add_argument("--w-max", type=float, required=True, metavar="W", help="highest frequency of interest [rad/s]")
    p.add_argument("--duration", type=float, metavar="S",
                   help="length of one run [s] (default: the recipe's max(90 s, 4.5 T_max))")
    p.add_argument("--amplitude", type=float, default=1.0, help="peak input amplitude in input units (default 1)")
    p.add_argument("--fade", type=float, metavar="S",
                   help="raised-cosine fade-in and fade-out [s] (default: in T_max/4; out the time the sweep needs "
                        "to pass w_max cleanly, never less); the fade-out lies above w_max")
    p.add_argument("--sample-rate", type=float, metavar="HZ",
                   help="samples per second (default: 25 per period of w_max, rounded up)")
    p.add_argument("--reduce-above", type=float, metavar="HZ",
                   help="reduce the amplitude from this input frequency on [Hz] (the report's pilots did above 1.5 Hz "
                        "to spare the rotor pylon mode); the change is smooth over the half octave below it")
    p.add_argument("--reduce-to", type=float, default=None, metavar="FRACTION",
                   help="the reduced amplitude as a fraction of --amplitude (default 0.5)")
    p.add_argument("--runs", type=int, default=2, help="runs to concatenate for the analysis (one more is flown)")
    p.add_argument("--name", default="input", help="input column name (default 'input')")
    p.add_argument("--out", required=True, metavar="FILE", help="the CSV to write (time_s, input)")
    p.add_argument("--json", metavar="FILE", help="also write the plan as JSON ('-' for standard output)")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")


def sweep_csv_text(t: Any, u: Any, name: str, header: str) -> str:
    """The rig's CSV: a first line naming synth, then ``time_s,<name>`` rows (time 6 decimals, input 9 digits).

    Examples
    --------
    >>> print(sweep_csv_text([0.0, 0.5], [0.0, 1.25], "pwm", "synth 1.0: sweep"), end="")
    # synth 1.0: sweep
    time_s,pwm
    0.000000,0
    0.500000,1.25
    """
    rows = "".join(f"{float(a):.6f},{float(b) + 0.0:.9g}\n" for a, b in zip(t, u))  # + 0.0: no "-0"
    return f"# {header}\ntime_s,{name}\n{rows}"


def _positive(value: float | None, flag: str, allow_zero: bool = False) -> None:
    from synth.errors import SynthError

    if value is None:
        return
    ok = math.isfinite(value) and (value >= 0 if allow_zero else value > 0)
    if not ok:
        raise SynthError(f"must be a {'non-negative' if allow_zero else 'positive'} number, got {value:g}", where=flag)


def run(args: argparse.Namespace) -> int:
    import dataclasses

    from synth.cli._outputs import check_outputs
    from synth.cli._table import name_values
    from synth.errors import DataError, SynthError
    from synth.ident.sweep_design import design_sweep
    from synth.outputs import GENERATOR, atomic_write_text, dump_json, write_json

    for value, flag in ((args.w_min, "--w-min"), (args.w_max, "--w-max"), (args.duration, "--duration"),
                        (args.amplitude, "--amplitude"), (args.sample_rate, "--sample-rate")):
        _positive(value, flag)
    _positive(args.fade, "--fade", allow_zero=True)
    _positive(args.reduce_above, "--reduce-above")
    if args.reduce_to is not None and args.reduce_above is None:
        raise SynthError("has no effect without --reduce-above (the frequency above which the amplitude is reduced)",
                         where="--reduce-to")
    if args.reduce_to is None:
        args.reduce_to = 0.5
    if args.reduce_above is not None and not (0 < args.reduce_to <= 1):
        raise SynthError(f"must be a fraction in (0, 1], got {args.reduce_to:g}", where="--reduce-to")
    if args.runs < 1:
        raise SynthError(f"must be at least 1, got {args.runs}", where="--runs")
    if not args.name.strip() or "," in args.name or "\n" in args.name:
        raise SynthError(f"not a usable column name: {args.name!r}", where="--name")
    if args.name.strip() == "time_s":
        raise SynthError("'time_s' is the time column's name; give the input another", where="--name")
    try:
        plan = design_sweep(args.w_min, args.w_max, args.runs)
    except DataError as exc:
        raise SynthError(exc.message, where="--w-min/--w-max") from None
    notes: list[str] = []
    low = plan.low_cycles * plan.t_max
    recommended = plan.run_length
    if args.duration is not None:
        if args.duration <= low:
            raise SynthError(f"{args.duration:g} s leaves no sweep after the two low-frequency cycles "
                             f"(2 T_max = {low:.4g} s); give more than that or raise --w-min", where="--duration")
        if args.duration < recommended:
            notes.append(f"the run is shorter than the recipe's {recommended:g} s: fewer averaging windows of 2 T_max")
            swept, recipe = args.duration - low, recommended - low
            if swept < SHORT_SWEEP * recipe:  # the two low cycles take nearly all of the run
                decades = math.log10(plan.w_max / plan.w_min)
                share = 100 * swept / recipe
                notes.append(f"a short sweep: after the two low-frequency cycles ({low:.4g} s) the sweep gets "
                             f"{swept:.3g} s for {decades:.2g} decades, {share:.2g} % of the recipe's {recipe:.4g} s: "
                             "every frequency above the lowest gets that share of its cycles (less coherence there); "
                             "a longer --duration or a higher --w-min")
        plan = dataclasses.replace(plan, run_length=float(args.duration))
    fade = 0.25 * plan.t_max if args.fade is None else float(args.fade)
    if 2 * fade >= plan.run_length:
        raise SynthError(f"fade-in plus fade-out ({2 * fade:g} s) must be shorter than the run ({plan.run_length:g} s)",
                         where="--fade")
    try:
        timing = plan.timing(args.fade)
    except DataError as exc:
        raise SynthError(exc.message, where="--fade" if args.fade is not None else "--duration") from None
    if timing.w_end > 2.0 * plan.w_max:
        notes.append(f"the fade-out ({timing.fade_out:.4g} s) carries the sweep on to {timing.w_end:.4g} rad/s, more "
                     "than twice w_max: a shorter --fade or a longer --duration keeps it nearer")
    if fade > plan.t_max:
        notes.append(f"the fade ({fade:g} s) is longer than T_max ({plan.t_max:.4g} s): the first low-frequency cycle "
                     "is mostly faded out")
    rate = args.sample_rate or plan.sample_rate
    samples = plan.run_length * rate + 1
    if samples > MAX_SAMPLES:
        raise SynthError(f"the run would hold {samples:,.0f} samples ({plan.run_length:g} s at {rate:.4g} Hz), over "
                         f"{MAX_SAMPLES:,}: narrow the frequency range (one sweep per part of it) or lower --sample-rate",
                         where="--sample-rate" if args.sample_rate else "--w-min/--w-max")
    if args.reduce_above is not None and 2.0 * math.pi * args.reduce_above <= plan.w_min * 2 ** 0.5:
        notes.append(f"--reduce-above {args.reduce_above:g} Hz is within half an octave of w_min "
                     f"({plan.w_min / (2 * math.pi):.3g} Hz): the low-frequency cycles are reduced too")
    try:
        reduce_above = None if args.reduce_above is None else 2.0 * math.pi * args.reduce_above
        t, u = plan.signal(amplitude=args.amplitude, sample_rate=rate, fade=args.fade, reduce_above=reduce_above,
                           reduce_to=args.reduce_to)
    except DataError as exc:
        where = "--sample-rate" if "sample rate" in exc.message else "--amplitude"
        raise SynthError(exc.message, where="--fade" if "f_end" in exc.message and not args.sample_rate else where) from None
    out = Path(args.out)
    check_outputs(None, files=[out, args.json], force=args.force)
    header = (f"{GENERATOR}: frequency sweep {plan.w_min:g}-{plan.w_max:g} rad/s, {plan.run_length:g} s, amplitude "
              f"{args.amplitude:g}, fade in {timing.fade_in:.4g} s, full amplitude to w_max at {timing.t_top:.4g} s, "
              f"fade out {timing.fade_out:.4g} s up to {timing.w_end:.4g} rad/s, {rate:g} Hz")
    if args.reduce_above is not None:
        header += f", amplitude x {args.reduce_to:g} above {args.reduce_above:g} Hz"
        if 2.0 * math.pi * args.reduce_above >= plan.w_max:
            notes.append(f"--reduce-above {args.reduce_above:g} Hz is at or above w_max: the sweep never gets there")
    if not out.parent.exists():
        raise SynthError("folder does not exist", where=str(out.parent))
    atomic_write_text(out, sweep_csv_text(t, u, args.name, header))
    data = {"generator": GENERATOR, **plan.to_dict(), "duration_s": plan.run_length, "amplitude": args.amplitude,
            "fade_s": fade, **timing.to_dict(), "reduce_above_hz": args.reduce_above,
            "reduce_to": args.reduce_to if args.reduce_above is not None else None, "sample_rate_hz": rate,
            "samples": int(t.size), "recommended_run_length_s": recommended,
            "csv": str(out), "column": args.name, "notes": notes}
    if args.json == "-":
        sys.stdout.write(dump_json(data))
        return 0
    if args.json:
        write_json(args.json, data, force=args.force)
    rows = [("frequency range", f"{plan.w_min:g}-{plan.w_max:g} rad/s ({plan.w_min / (2 * math.pi):.3g}-"
                                f"{plan.f_max:.3g} Hz)"),
            ("longest period T_max", f"{plan.t_max:.4g} s (2 cycles at the start: {low:.4g} s)"),
            ("run length", f"{plan.run_length:g} s (recipe: {recommended:g} s)"),
            ("runs", f"fly {plan.runs_flown}, concatenate the best {plan.runs_used}"),
            ("swept at full amplitude", f"{plan.w_min:g}-{plan.w_max:g} rad/s (w_max at {timing.t_top:.4g} s)"),
            ("amplitude", f"{args.amplitude:g} peak, fade in {timing.fade_in:.4g} s (raised cosine)"),
            ("fade-out", f"{timing.fade_out:.4g} s (raised cosine) above w_max, sweeping on to {timing.w_end:.4g} rad/s"
                         f" ({timing.w_end / (2 * math.pi):.3g} Hz); ends at rest"),
            ("sample rate", f"{rate:g} Hz, {t.size} samples"),
            ("analysis windows", ", ".join(f"{w:.3g}" for w in plan.windows) + " s")]
    print(name_values(rows, notes))
    print(f"wrote {out}" + (f" and {args.json}" if args.json else ""))
    return 0
