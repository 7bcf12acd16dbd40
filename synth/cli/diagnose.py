"""``synth diagnose --plant MODEL --data RUN.csv``: where a model and the hardware disagree, and why."""

from __future__ import annotations

import argparse
import os
import shlex
import sys
from pathlib import Path
from typing import Any

__all__ = ["COMMAND", "DESCRIPTION", "HELP", "ORDER", "Interrupted", "add_arguments", "partial_result", "run"]

COMMAND = "diagnose"
ORDER = 50
HELP = "sim-to-real gap: where the model and a measured record disagree, and which effect explains it"
DESCRIPTION = """Diagnose the gap between a linear model and a measured record.

The model is driven by the measured command (--input) and compared with the
measured output (--output). Prints the size of the gap (NRMSE), where it lies
(time windows, frequency bands, regimes such as input rate or an --aux
channel) and which unmodelled effect explains it (rate limit, saturation,
delay, lag, ...): each candidate is fitted together with the nominal
coefficients and judged by how far it shrinks the error on held-out data (the
second half of the record, or --validate). Writes result.json, report.html,
gap_map.png and overlay.png into --out (default reports/diagnose/<data file
stem>/). Files synth did not write are never overwritten (use --force).

MODEL is a transfer function ("23*(s+0.43)/((s+9.6)*(s+0.54))", with
--delay), the JSON of `synth identify --json`, or a spec file (its plant).

example:
  synth diagnose --plant "23*(s+0.43)/((s+9.6)*(s+0.54))" --data run.csv \\
      --time t --input pwm --output speed --aux current --json gap.json
  synth diagnose --plant identify.json --data run1.csv --validate run2.csv \\
      --candidates rate_limit,saturation,delay
  synth diagnose --plant "246/((0.167*s+1)*(0.166*s+1))" --data open_loop.mat \\
      --validate closed_1.mat --validate closed_2.mat --round-robin

--validate may be given several times (runs of the same plant: each keeps its
own output offset). With --round-robin, --data and every --validate run take
turns: each is fitted once and the others are held out, and the evidence is
pooled; this confirms an effect of the transients (a delay, a lag) from runs
that hold one step each. The round robin writes result.json, report.html and
each fold's overlay (fold_<k>.png).

Before any fitting the model is checked: an unstable or non-simulable model,
a delay longer than the record, or a record too short for a candidate is one
line and exit 2. --aux columns may drive effects: measured_sag(COL) (the drive
scales with a measured supply) and aux_input(COL) (a measured disturbance at
the input) join the default candidates, and the verdict says which channel
explained how much. On SIGTERM or SIGINT the worker processes are terminated
and, with --json, what was finished is written there marked "partial".

exit codes: 0 diagnosed (whatever the verdict), 2 bad input, 128 + the signal
number when interrupted (143 SIGTERM, 130 SIGINT)"""


class Interrupted(BaseException):
    """Raised in the main thread by the SIGTERM/SIGINT handler of ``synth diagnose`` (not an ``Exception``:
    no library ``except Exception`` swallows it)."""

    def __init__(self, signum: int) -> None:
        import signal

        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--plant", required=True, metavar="MODEL",
                   help="transfer function, synth identify JSON, or spec file (.yaml)")
    p.add_argument("--delay", type=float, metavar="S",
                   help="delay [s]: added to a transfer function, replaces a file's delay")
    p.add_argument("--data", required=True, metavar="FILE", help="measured record: CSV with a header row, or MAT")
    p.add_argument("--validate", metavar="FILE", action="append",
                   help="held-out record with the same columns, repeatable: several runs (default: the second "
                        "half of --data is held out)")
    p.add_argument("--time", metavar="COL", help="time column (default: the first)")
    p.add_argument("--input", metavar="COL", help="measured command column (default: the second)")
    p.add_argument("--output", metavar="COL", help="measured output column (default: the third)")
    p.add_argument("--dt", type=float, metavar="S",
                   help="sample interval when the files have no time column (input and output default to the first "
                        "two columns)")
    p.add_argument("--aux", metavar="COL", action="append", default=[],
                   help="extra logged channel (current, voltage, ...); repeat or separate by commas")
    p.add_argument("--columns", metavar="OLD=NEW,...", action="append", default=[],
                   help="rename columns before picking them, e.g. acc[0]=accel_x (a MAT matrix gives acc[0], "
                        "acc[1], ...); applies to --data and every --validate record")
    p.add_argument("--input-unit", default="", metavar="UNIT", help="unit of the input, e.g. PWM or V")
    p.add_argument("--output-unit", default="", metavar="UNIT", help="unit of the output, e.g. rad/s")
    p.add_argument("--candidates", metavar="A,B,...",
                   help="effects to try (default: delay, lag, lag(sensor), resonance, rate_limit, saturation, "
                        "deadzone, backlash, quantization, supply_sag, static_nonlinearity, drift, and with --aux COL "
                        "measured_sag(COL), aux_input(COL); by name only: direction, duffing, amplitude_damping, "
                        "friction, saturation(output))")
    p.add_argument("--seed", type=int, default=0, help="seed of the bootstrap (default 0)")
    p.add_argument("--split", choices=("tail", "interleaved"), default="tail",
                   help="without --validate: hold out the second half (tail, default) or every second of "
                        "20 segments (interleaved, for a record with one transient)")
    p.add_argument("--burn-in", type=float, default=0.0, metavar="S",
                   help="seconds at the start of each record left out of every cost (unknown initial state)")
    p.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1), metavar="N",
                   help="processes for the joint re-fits and the quantizer's search; 1: everything in this one "
                        "process (default: 2, or 1 on a one-core machine)")
    p.add_argument("--heldout-offset", choices=("auto", "carry", "fit"), default="auto",
                   help="output offset on held-out data: re-estimated per model (fit), kept from the training "
                        "fit (carry), or auto: fit with --validate (another run, its own sensor zero), else carry")
    p.add_argument("--round-robin", action="store_true",
                   help="--data and every --validate run take turns: each fitted once, the others held out, "
                        "the evidence pooled (at least one --validate)")
    p.add_argument("--max-effects", type=int, default=2, metavar="N",
                   help="effects a verdict may name (forward selection; default 2)")
    p.add_argument("--out", metavar="DIR", help="folder for the report (default reports/diagnose/<data file stem>)")
    p.add_argument("--json", metavar="FILE", help="also write the JSON to FILE ('-' for standard output)")
    p.add_argument("--no-report", action="store_true", help="write no report folder")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing; use the exit code")


def _split(values: list[str]) -> list[str]:
    return [v.strip() for item in values for v in item.split(",") if v.strip()]


def run(args: argparse.Namespace) -> int:
    from synth.data import load_record
    from synth.data.readers import parse_column_map
    from synth.errors import SynthError
    from synth.forked import allow_fork
    from synth.gap.diagnose import check_candidates, diagnose, load_model
    from synth.outputs import dump_json, write_json

    if args.workers < 1:
        raise SynthError(f"must be at least 1, got {args.workers}", where="--workers")
    if args.seed < 0:
        raise SynthError(f"must be an integer >= 0, got {args.seed}", where="--seed")
    if args.workers == 1:  # one process: no forked child for the quantizer's search either (synth.forked)
        allow_fork(False)
    try:
        candidates = check_candidates(_split([args.candidates])) if args.candidates is not None else None
    except SynthError as exc:
        raise SynthError(exc.message, where="--candidates") from None
    from synth.cli._outputs import check_outputs

    stem = Path(args.data).stem + ("_round_robin" if args.round_robin else "")
    check_outputs(None if args.no_report else Path(args.out or Path("reports") / "diagnose" / stem),
                  ["result.json", "report.html"], [args.json], args.force,
                  inputs=[args.data])  # refuse before the slow part
    plant = load_model(args.plant, args.delay, where="--plant")
    aux = _split(args.aux)
    kw: dict[str, Any] = {"aux": aux, "input_unit": args.input_unit, "output_unit": args.output_unit,
                          "columns": parse_column_map(args.columns), "dt": args.dt}
    record = load_record(args.data, args.time, args.input, args.output, **kw)
    validates = [load_record(v, args.time, args.input, args.output, **kw) for v in args.validate or []]
    if args.round_robin:
        return _round_robin(args, plant, [record, *validates], candidates)
    validate = validates if len(validates) > 1 else (validates[0] if validates else None)
    progress: dict[str, Any] = {}
    try:
        with _SignalsRaise(), _ProgressBar(progress, not args.quiet and sys.stderr.isatty()):
            diag = diagnose(plant, record, validate, candidates, seed=args.seed, split=args.split,
                            burn_in=args.burn_in, max_effects=args.max_effects, workers=args.workers,
                            heldout_offset=args.heldout_offset, progress=progress)
    except Interrupted as exc:
        return _interrupted(args, exc, progress)
    data = diag.to_dict()
    held = [str(v) for v in args.validate or []]
    data = {"data": str(args.data), "validate_data": held if len(held) > 1 else (held[0] if held else None),
            "plant_argument": args.plant, **data}
    report = None
    if not args.no_report:
        from synth.gap.report import write_diagnosis_report

        out_dir = Path(args.out) if args.out else Path("reports") / "diagnose" / Path(args.data).stem
        command = _command(args)
        report = write_diagnosis_report(diag, out_dir, command=command, force=args.force,
                                        title=f"{Path(args.data).name} against {plant.to_string()}",
                                        extra={k: data[k] for k in ("data", "validate_data", "plant_argument")})
    if args.json == "-":
        sys.stdout.write(dump_json(data))
    elif args.json:
        write_json(args.json, data, force=args.force)
    if not args.quiet and args.json != "-":
        _print(data, report)
    return 0


class _ProgressBar:
    """A progress bar on standard error while the diagnosis runs (shown after 2 s; the steps of ``progress``).

    A thread reads ``progress`` (``"stage"``, and during the attribution ``"done"`` of ``"total"`` steps and
    the last ``"step"``) four times a second; nothing is drawn when ``enabled`` is false.
    """

    def __init__(self, progress: dict[str, Any], enabled: bool) -> None:
        self.progress, self.enabled = progress, enabled

    def __enter__(self) -> None:
        if not self.enabled:
            return
        import threading

        from tqdm import tqdm

        self.stop = threading.Event()
        self.bar = tqdm(total=1, desc="diagnose", unit="step", delay=1e9, file=sys.stderr, leave=False,
                        bar_format="{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} [{elapsed}]")

        def poll() -> None:
            if self.stop.wait(2.0):  # a short run draws no bar
                return
            while not self.stop.wait(0.25):
                p = self.progress
                total, done = int(p.get("total", 0) or 0), int(p.get("done", 0) or 0)
                stage = str(p.get("stage", "start"))
                desc = f"diagnose: {stage}" + (f" ({p['step']} done)" if stage == "attribution" and "step" in p else "")
                if total and (total != self.bar.total or done != self.bar.n):
                    self.bar.total = total
                    self.bar.n = min(done, total)
                self.bar.set_description_str(desc, refresh=False)
                self.bar.refresh()

        self.thread = threading.Thread(target=poll, daemon=True)
        self.thread.start()

    def __exit__(self, *exc: Any) -> None:
        if not self.enabled:
            return
        self.stop.set()
        self.thread.join()
        self.bar.close()


class _SignalsRaise:
    """Within the block, SIGTERM and SIGINT raise :class:`Interrupted` in the main thread (handlers restored after)."""

    def __enter__(self) -> None:
        import os
        import signal
        import threading

        owner = os.getpid()

        def handler(signum: int, frame: Any) -> None:
            if os.getpid() != owner:  # a worker forked with this handler, hit before it set its own: leave quietly
                os._exit(128 + signum)  # (the command reports the interruption; a traceback here would be noise)
            raise Interrupted(signum)

        self.old = {}
        if threading.current_thread() is threading.main_thread():  # handlers can only be set there
            self.old = {s: signal.signal(s, handler) for s in (signal.SIGTERM, signal.SIGINT)}

    def __exit__(self, *exc: Any) -> None:
        import signal

        for s, h in self.old.items():
            signal.signal(s, h)


def partial_result(progress: dict[str, Any], signal_name: str, data: str) -> dict[str, Any]:
    """What an interrupted diagnosis kept: ``partial``, ``interrupted_by``, ``kept``, ``missing`` and the kept parts.

    Examples
    --------
    >>> d = partial_result({"stage": "localization"}, "SIGTERM", "run.csv")
    >>> d["partial"], d["kept"], d["missing"]
    (True, [], ['gap', 'where', 'effects', 'verdict'])
    """
    out: dict[str, Any] = {"partial": True, "interrupted_by": signal_name, "data": data,
                           "stage": progress.get("stage", "start")}
    loc = progress.get("localization")
    if loc is not None:
        d = loc.to_dict()
        out.update(gap=d["gap"], where=d["where"], headline=d["headline"])
    out["kept"] = [k for k in ("gap", "where") if k in out]
    out["missing"] = [k for k in ("gap", "where", "effects", "verdict") if k not in out]
    return out


def _interrupted(args: argparse.Namespace, exc: Interrupted, progress: dict[str, Any]) -> int:
    from synth.outputs import dump_json, write_json

    data = partial_result(progress, str(exc), str(args.data))
    kept = ", ".join(data["kept"]) or "nothing"
    where = ""
    if args.json == "-":
        sys.stdout.write(dump_json(data))
    elif args.json:
        write_json(args.json, data, force=args.force)
        where = f" to {args.json}"
    print(f"synth diagnose: interrupted by {exc} during the {data['stage']}; kept {kept}{where if data['kept'] else ''}"
          f" (partial; missing: {', '.join(data['missing'])})", file=sys.stderr)
    return 128 + exc.signum


def _round_robin(args: argparse.Namespace, plant: Any, runs: list[Any], candidates: list[str] | None) -> int:
    from synth.errors import SynthError
    from synth.gap.attribution.roundrobin import diagnose_runs
    from synth.gap.effects.registry import DEFAULT_CANDIDATES
    from synth.outputs import dump_json, write_json

    if len(runs) < 2:
        raise SynthError("needs at least one --validate run besides --data", where="--round-robin")
    files = [str(args.data), *(str(v) for v in args.validate or [])]
    names = [Path(f).name for f in files]
    from synth.gap.effects.registry import make_effect
    from synth.gap.preflight import check_model

    effects = [make_effect(c) for c in candidates or DEFAULT_CANDIDATES]
    for run in runs:  # every run is fitted once, whole: refuse before any fit
        check_model(plant, run, effects, validated=True)
    try:
        with _SignalsRaise():
            rr = diagnose_runs(plant, runs, candidates or list(DEFAULT_CANDIDATES), names=names, seed=args.seed,
                               burn_in=args.burn_in, workers=args.workers)
    except Interrupted as exc:
        return _interrupted(args, exc, {"stage": "round robin"})
    data = {"runs_data": files, "plant_argument": args.plant,
            "units": {"input": runs[0].input.unit, "output": runs[0].output.unit}, **rr.to_dict()}
    report = None
    if not args.no_report:
        from synth.gap.roundrobin_report import write_runs_report

        out_dir = Path(args.out) if args.out else Path("reports") / "diagnose" / f"{Path(args.data).stem}_round_robin"
        report = write_runs_report(rr, out_dir, units=data["units"], command=_command(args), force=args.force,
                                   title=f"{', '.join(names)} against {plant.to_string()}",
                                   extra={k: data[k] for k in ("runs_data", "plant_argument", "units")})
    if args.json == "-":
        sys.stdout.write(dump_json(data))
    elif args.json:
        write_json(args.json, data, force=args.force)
    if not args.quiet and args.json != "-":
        v = data["verdict"]
        print(data["summary"])
        print(f"verdict: {', '.join(v['effects']) if v['effects'] else 'none'} ({v['status']}): {v['headline']}")
        for fold in data["folds"]:
            fv = fold["verdict"]
            print(f"  trained on {fold['train']}: {', '.join(fv['effects']) if fv['effects'] else 'none'} "
                  f"({fv['status']})")
        if report is not None:
            print(f"\nreport: {report.html}")
    return 0


def _command(args: argparse.Namespace) -> str:
    parts = ["synth", "diagnose"]
    for opt in ("plant", "delay", "data", "validate", "time", "input", "output", "input_unit", "output_unit",
                "candidates", "out"):
        value = getattr(args, opt)
        for item in (value if isinstance(value, list) else [value]):
            if item not in (None, ""):
                parts += [f"--{opt.replace('_', '-')}", shlex.quote(str(item))]
    parts += ["--round-robin"] if args.round_robin else []
    for a in _split(args.aux):
        parts += ["--aux", shlex.quote(a)]
    for c in args.columns:
        parts += ["--columns", shlex.quote(c)]
    extra = [f"--seed {args.seed}"] if args.seed else []
    extra += [f"--split {args.split}"] if args.split != "tail" else []
    extra += [f"--burn-in {args.burn_in:g}"] if args.burn_in else []
    extra += [f"--max-effects {args.max_effects}"] if args.max_effects != 2 else []
    extra += [f"--heldout-offset {args.heldout_offset}"] if args.heldout_offset != "auto" else []
    return " ".join(parts + extra)


def _print(d: dict[str, Any], report: Any) -> None:
    v = d["verdict"]
    print(d["summary"])
    for w in d.get("warnings", []):
        print(f"warning: {w}")
    print(f"where: {d['headline']}")
    print(f"verdict: {', '.join(v['effects']) if v['effects'] else 'none'} ({v['status']}): {v['headline']}")
    if v.get("observed"):
        print(f"seen in the data: {', '.join(v['observed'])} (clipped signals: see the summary)")
    for group, experiment in zip(v["indistinguishable"], v["experiments"] or [""] * len(v["indistinguishable"])):
        print(f"indistinguishable: {' / '.join(group)}{'; separate by ' + experiment if experiment else ''}")
    for a in v.get("aux", []):
        lo, hi = a["shrinkage_ci"]
        print(f"aux {a['channel']}: {a['effect']} shrinkage {a['shrinkage']:+.3f} [{lo:+.3f}, {hi:+.3f}]"
              f"{'  accepted' if a['accepted'] else ''}")
    for nc in v.get("not_carried", []):
        print(f"not in the verdict: {nc['effect']} ({nc['shrinkage']:+.2f}): {nc['reason']}")
    for e in d["effects"][:3]:
        lo, hi = e["shrinkage_ci"]
        params = ", ".join(f"{k} = {x:.4g}" if isinstance(x, float) else f"{k} = {x}" for k, x in e["parameters"].items()
                           if k not in ("center", "scale"))
        print(f"  {e['effect']:<20} shrinkage {e['shrinkage']:+.3f} [{lo:+.3f}, {hi:+.3f}]  {params}"
              f"{'  accepted' if e['accepted'] else ''}")
    if report is not None:
        print(f"\nreport: {report.html}")
