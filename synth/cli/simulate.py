"""``synth simulate SPEC --controller "P(3)" --step 820:920``: the sampled nonlinear closed loop."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

__all__ = ["COMMAND", "DESCRIPTION", "EXIT_CODES", "HELP", "ORDER", "add_arguments", "run"]

COMMAND = "simulate"
ORDER = 30
HELP = "simulate the sampled nonlinear closed loop of a spec (rate limit, saturation, sensor, delay)"
DESCRIPTION = """Simulate a step of the sampled nonlinear closed loop described by the spec's
`simulation:` block (actuator and sensor blocks, operating point, controller rate,
in-loop delay; see docs/simulation.md) and report the step metrics: rise time,
overshoot, settling time, peak actuator rate and amplitude, time rate-limited
and saturated, and whether the run ends in a limit cycle (amplitude, period).

The horizon follows the dynamics: the first one is read from the linear loop's
slowest visible mode and the period at which the loop's phase is -180 deg (where a
limit cycle would sit), or is --horizon / simulation.horizon when given; it is
doubled until the run decides - settled, limit cycle (amplitude and period steady
over the last two quarters), diverging - or the cap (--max-horizon) is reached:
then the verdict is "undetermined within N s". Each verdict prints its evidence
(horizons tried, samples, cycles seen, the rule that decided).

Writes the time series (CSV) and a plot (PNG) into --out (default
reports/<spec name>/simulate/); --csv and --plot put them elsewhere. Files
synth did not write are never overwritten (use --force).

example:
  synth simulate specs/x4_rotor.yaml --controller "P(3)" --step 820:920
  synth simulate specs/x4_rotor.yaml -c "P(8)" --delay 0.015 --json -
  synth simulate specs/x4_rotor.yaml --sweep kp=1:12:23 --json sweep.json

exit codes: 0 settles, 1 ends in a sustained oscillation or diverges, 2 bad input,
3 undetermined within the cap (with --sweep: 1 if any run oscillates or diverges,
else 3 if any is undetermined)"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("spec", help="spec file (YAML)")
    p.add_argument("--controller", "-c",
                   help='controller, e.g. "P(3)" (default: the spec\'s reference controller)')
    p.add_argument("--step", metavar="FROM:TO", help="reference step in output units (default: simulation.step)")
    p.add_argument("--horizon", type=float, metavar="S",
                   help="first simulated horizon in seconds, extended until the verdict is determined "
                   "(default: simulation.horizon if the spec sets it, else from the loop's dynamics)")
    p.add_argument("--max-horizon", type=float, metavar="S",
                   help="longest horizon tried before answering 'undetermined' (default: 64 times the first "
                   "horizon, at least 200 slowest plant time constants and 60 s, at most 1e6 samples)")
    p.add_argument("--step-time", type=float, metavar="S", help="time of the step (default: simulation.step_time)")
    p.add_argument("--delay", type=float, metavar="S",
                   help="in-loop delay in seconds (default: simulation.loop_delay)")
    p.add_argument("--sweep", metavar="NAME=LO:HI:N",
                   help="simulate N values of a controller parameter at once (geometric spacing), e.g. kp=1:12:23")
    p.add_argument("--out", metavar="DIR", help="folder for timeseries.csv and step.png "
                   "(default reports/<spec name>/simulate)")
    p.add_argument("--csv", metavar="FILE", help="write the time series to FILE instead")
    p.add_argument("--plot", metavar="FILE", help="write the plot to FILE instead")
    p.add_argument("--json", metavar="FILE", help="write the metrics as JSON to FILE ('-' for standard output)")
    p.add_argument("--force", action="store_true", help="overwrite files synth did not write")
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing; use the exit code")


def _step(text: str) -> tuple[float, float]:
    import math

    from synth.errors import SynthError

    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = float(parts[0]), float(parts[1])
        if not (math.isfinite(a) and math.isfinite(b)):
            raise ValueError
        return a, b
    except ValueError:
        raise SynthError(f"expected FROM:TO in output units, e.g. 820:920, got {text!r}", where="--step") from None


def _sweep(text: str, controller: Any) -> tuple[str, list[float]]:
    import numpy as np

    from synth.errors import SynthError

    try:
        name, rng = text.split("=", 1)
        lo, hi, n = rng.split(":")
        lo_f, hi_f, count = float(lo), float(hi), int(n)
    except ValueError:
        raise SynthError(f"expected NAME=LO:HI:N, e.g. kp=1:12:23, got {text!r}", where="--sweep") from None
    name = name.strip()
    if name not in controller.parameters:
        raise SynthError(f"{controller.type} has no parameter {name!r}; its parameters are "
                         f"{', '.join(controller.parameters)}", where="--sweep")
    if not (0 < lo_f < hi_f) or count < 2 or count > 10000:
        raise SynthError(f"need 0 < LO < HI and 2 <= N <= 10000, got {text!r}", where="--sweep")
    return name, [float(v) for v in np.geomspace(lo_f, hi_f, count)]


def _ours(path: Path) -> bool:
    """A file synth wrote: a CSV starting with '# synth', a PNG tagged Software=synth."""
    try:
        head = path.read_bytes()[:4096]
    except OSError:
        return False
    return head.startswith(b"# synth") or b"Software\x00synth" in head


def _claim(path: Path, force: bool) -> Path:
    from synth.errors import OutputExistsError

    if path.is_dir():
        raise OutputExistsError("is a directory", where=str(path))
    if path.exists() and not force and not _ours(path):
        raise OutputExistsError("exists and was not written by synth; not overwriting it (use --force)",
                                where=str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _write_csv(path: Path, columns: dict[str, Any], header: str) -> None:
    import numpy as np

    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], float) for n in names])
    with path.open("w", encoding="utf-8") as fh:
        fh.write(f"# {header}\n")
        fh.write(",".join(names) + "\n")
        np.savetxt(fh, data, delimiter=",", fmt="%.10g")


def run(args: argparse.Namespace) -> int:
    from synth.cli._outputs import check_outputs, spec_name
    from synth.controllers import Controller
    from synth.errors import ModelError, SynthError
    from synth.outputs import GENERATOR, OutputDir, dump_json, to_jsonable, write_json
    from synth.sim.spec import SimulationSpec
    from synth.spec import load_spec

    name = args.out or spec_name(args.spec)  # refuse before any computation
    folder_names = (["sweep.json"] + ([] if args.csv else ["sweep.csv"]) if args.sweep else
                    ["metrics.json"] + ([] if args.csv else ["timeseries.csv"]) + ([] if args.plot else ["step.png"]))
    uses_folder = not args.csv if args.sweep else not (args.csv and args.plot)
    check_outputs((Path(args.out) if args.out else Path("reports") / name / "simulate") if name and uses_folder
                  else None, folder_names, [args.json, args.csv, None if args.sweep else args.plot], args.force,
                  inputs=[args.spec])
    spec = load_spec(args.spec)
    sim = spec.simulation or SimulationSpec()
    text = args.controller or (spec.reference.controller if spec.reference else None)
    if text is None:
        raise SynthError("give a controller, e.g. --controller \"P(3)\" (the spec has no reference controller)",
                         where="--controller")
    try:
        controller = Controller.from_string(text)
    except ModelError as exc:
        raise exc.located("--controller") from None
    step = _step(args.step) if args.step else sim.default_step()
    given = args.horizon if args.horizon is not None else (sim.horizon if "horizon" in sim.model_fields_set else None)
    t_step = sim.step_time if args.step_time is None else args.step_time
    _check_times(args, given, t_step, sim.dt)
    loop = sim.build_loop(spec.nominal_plant(), controller, str(controller))
    if args.delay is not None:
        loop = loop.replace(loop_delay=args.delay)
    disturbances = sim.build_disturbances()
    say = (lambda *a: None) if args.quiet or args.json == "-" else print
    if args.sweep:
        from synth.sim.horizon import plan_horizon

        horizon = given if given is not None else plan_horizon(loop, t_step).horizon
        return _run_sweep(args, spec, sim, loop, step, horizon, t_step, disturbances, say)

    from synth.sim.metrics import unsettled
    from synth.sim.verdict import step_verdict

    try:
        v = step_verdict(loop, step[0], step[1], t_step, given, args.max_horizon, disturbances, sim.seed,
                         sim.limit_cycle.min_amplitude, sim.limit_cycle.window)
    except ModelError as exc:
        where = "--horizon" if exc.message.startswith("horizon ") and args.horizon is not None else (
            "--max-horizon" if args.max_horizon is not None else "simulation")
        raise exc.located(where) from None
    result, metrics = v.result, (v.metrics if v.verdict == "settled" else unsettled(v.metrics))
    payload = {"spec": spec.name, "controller": str(controller), "step": list(step), "step_time": t_step,
               "horizon": v.evidence.horizon, "loop": loop.to_dict(), "verdict": v.verdict,
               "evidence": v.evidence.to_dict(), **metrics.to_dict()}
    out_dir = Path(args.out) if args.out else Path("reports") / spec.name / "simulate"
    folder = OutputDir(out_dir, args.force) if not (args.csv and args.plot) else None
    csv_path = _claim(Path(args.csv), args.force) if args.csv else folder.claim("timeseries.csv")  # type: ignore[union-attr]
    plot_path = _claim(Path(args.plot), args.force) if args.plot else folder.claim("step.png")  # type: ignore[union-attr]
    _write_csv(csv_path, result.series(), f"{GENERATOR}: {spec.name}, {controller}, step {step[0]:g} -> "
               f"{step[1]:g} at {t_step:g} s")
    _plot(result, loop, metrics, step, spec, plot_path)
    if folder is not None:
        json_path = folder.claim("metrics.json")
        json_path.write_text(dump_json(payload), encoding="utf-8")
        folder.commit()
    if args.json == "-":
        sys.stdout.write(dump_json(to_jsonable(payload)))
    elif args.json:
        write_json(args.json, payload, force=args.force)
    _print_metrics(say, spec, loop, metrics, step, v.verdict)
    say(f"\nverdict: {v.summary(spec.plant.output.unit)}\nfirst horizon: {v.evidence.plan.reason}")
    if folder is not None:
        csv_path, plot_path = folder.final(csv_path), folder.final(plot_path)
    say(f"\ntime series: {csv_path}\nplot: {plot_path}")
    return EXIT_CODES[v.verdict]


EXIT_CODES = {"settled": 0, "limit_cycle": 1, "diverging": 1, "undetermined": 3}
"""Exit code of each verdict (2 is bad input)."""


def _check_times(args: argparse.Namespace, given: float | None, t_step: float, dt: float) -> None:
    """One-line errors for horizons and delays that cannot be simulated."""
    import math

    from synth.errors import SynthError
    from synth.sim.verdict import MAX_SAMPLES

    for name, value in (("--horizon", args.horizon), ("--max-horizon", args.max_horizon),
                        ("--step-time", args.step_time), ("--delay", args.delay)):
        if value is not None and not math.isfinite(value):
            raise SynthError(f"must be a finite number of seconds, got {value:g}", where=name)
    if given is not None and not given > 0:
        raise SynthError(f"must be > 0 s, got {given:g}", where="--horizon")
    if given is not None and not 0 <= t_step < given:
        raise SynthError(f"must be in [0, horizon), got {t_step:g} s", where="--step-time")
    if t_step < 0:
        raise SynthError(f"must be >= 0 s, got {t_step:g}", where="--step-time")
    if args.max_horizon is not None and not args.max_horizon > t_step:
        raise SynthError(f"must be after the step ({t_step:g} s), got {args.max_horizon:g}", where="--max-horizon")
    if given is not None and args.max_horizon is not None and args.max_horizon < given:
        raise SynthError(f"must be at least the horizon ({given:g} s), got {args.max_horizon:g}", where="--max-horizon")
    if args.horizon is not None and dt > args.horizon / 20:
        raise SynthError(f"dt {dt:g} s must be at most 1/20 of the horizon, got {args.horizon:g} s", where="--horizon")
    if t_step / dt > 10 * MAX_SAMPLES:
        raise SynthError(f"{t_step:g} s is {t_step / dt:.3g} samples of {dt:g} s; at most {10 * MAX_SAMPLES:.3g}",
                         where="--step-time")
    for name, value in (("--horizon", given), ("--max-horizon", args.max_horizon)):
        if value is not None and value / dt > 10 * MAX_SAMPLES:
            raise SynthError(f"{value:g} s is {value / dt:.3g} samples of {dt:g} s; at most {10 * MAX_SAMPLES:.3g}",
                             where=name)
    if args.delay is not None and (args.delay < 0 or args.delay / dt > MAX_SAMPLES):
        raise SynthError(f"must be >= 0 s and at most {MAX_SAMPLES:.3g} samples, got {args.delay:g}", where="--delay")


def _print_metrics(say: Any, spec: Any, loop: Any, m: Any, step: tuple[float, float], verdict: str) -> None:
    from synth.cli._table import table
    from synth.requirements.base import fmt

    u = spec.plant.input.unit or "input units"
    y = spec.plant.output.unit or "output units"
    lc = m.limit_cycle
    cycle = {"limit_cycle": f"{fmt(lc.amplitude)} {y} every {fmt(lc.period)} s" if lc.present else "yes",
             "diverging": "diverges", "settled": "none", "undetermined": "undetermined"}[verdict]
    settling = f"{fmt(m.settling_time)} s" if m.settling_time is not None else "not settled"
    timing = [f"{fmt(m.rise_time)} s", f"{fmt(m.overshoot)} %", settling] if step[0] != step[1] else \
        ["n/a: the reference does not step"] * 3
    if verdict != "settled" and step[0] != step[1]:
        timing = ["n/a: the step does not settle"] * 2 + ["not settled"]
    elif step[0] != step[1] and m.rise_time != m.rise_time:  # NaN: the output did not move
        timing = ["n/a: the output does not move"] * 3
    rows = [
        ["rise time 10-90 %", timing[0]],
        ["overshoot", timing[1]],
        ["settling time (2 %)", timing[2]],
        ["final value", f"{fmt(m.final_value)} {y}" if verdict == "settled" else
         f"none: it oscillates about {fmt(lc.center)} {y} (the mean of its last whole cycles)"
         if verdict == "limit_cycle" and lc.center is not None else f"none: {verdict.replace('_', ' ')}"],
        ["peak actuator rate", f"{fmt(m.actuator_peak_rate)} {u}/s"],
        ["actuator range", f"{fmt(m.actuator_min)} to {fmt(m.actuator_max)} {u}"],
        ["time rate-limited", f"{fmt(m.rate_limited_time)} s"],
        ["time saturated", f"{fmt(m.saturated_time)} s"],
        ["limit cycle", cycle],
    ]
    say(f"{spec.name}: {loop.controller}, step {fmt(step[0])} -> {fmt(step[1])} {y}, in-loop delay "
        f"{fmt(loop.loop_delay * 1000)} ms")
    say(table(["metric", "value"], rows))


def _plot(result: Any, loop: Any, metrics: Any, step: tuple[float, float], spec: Any, path: Path) -> None:
    import dataclasses

    import numpy as np

    from synth.sim.figures import step_comparison
    from synth.sim.simulator import simulate_step

    linear = simulate_step(loop.linear(), step[0], step[1], float(result.t[-1]))
    masked = {}
    for name in ("output", "actuator"):  # a diverging linear loop: drawn only while near the nonlinear range
        ours, theirs = np.asarray(getattr(result, name), float), np.array(getattr(linear, name), float)
        lo, hi = float(np.min(ours)), float(np.max(ours))
        span = max(hi - lo, abs(step[1] - step[0]), 1e-12)
        with np.errstate(invalid="ignore"):
            theirs[~(np.abs(theirs - 0.5 * (lo + hi)) <= 20 * span)] = np.nan
        masked[name] = theirs
    linear = dataclasses.replace(linear, **masked)
    units = {"input": spec.plant.input.unit, "output": spec.plant.output.unit}
    step_comparison({str(loop.controller): {"nonlinear": result, "linear": linear}}, path, units)


def _run_sweep(args: argparse.Namespace, spec: Any, sim: Any, loop: Any, step: tuple[float, float], horizon: float,
               t_step: float, disturbances: list[Any], say: Any) -> int:
    from tqdm import tqdm

    from synth.cli._table import table
    from synth.outputs import GENERATOR, OutputDir, dump_json, to_jsonable, write_json
    from synth.requirements.base import fmt
    from synth.sim.hidden_mode import unseen_root
    from synth.sim.metrics import nonlinear_step_metrics, unsettled
    from synth.sim.signals import step_reference
    from synth.sim.simulator import simulate_batch
    from synth.sim.verdict import judge, step_verdict

    name, values = _sweep(args.sweep, loop.controller)
    loops = [loop.with_gain(name, v) for v in values]
    rows, entries = [], []
    chunk = 50
    show = not (args.quiet or args.json == "-") and len(loops) > chunk
    bar = tqdm(total=len(loops), desc="simulating", unit="run", disable=not show, file=sys.stderr)
    series: dict[str, Any] = {}
    for start in range(0, len(loops), chunk):
        batch = simulate_batch(loops[start:start + chunk], step_reference(step[0], step[1], t_step), horizon,
                               disturbances, sim.seed)
        for i, res in enumerate(batch):
            window = sim.limit_cycle.window or (horizon - t_step) / 4
            m = nonlinear_step_metrics(res, t_step, min_amplitude=sim.limit_cycle.min_amplitude, window=window,
                                       step_size=step[1] - step[0])
            j = judge(res, t_step, step, m, sim.limit_cycle.min_amplitude, actuator=loops[start + i].actuator,
                      unseen_root=unseen_root(loops[start + i]))
            value = values[start + i]
            verdict = j.verdict
            evidence: dict[str, Any] = {"horizon": float(res.t[-1]), "dt": res.dt, "samples": int(res.t.size),
                                        "cycles": j.cycles, "horizons": [float(res.t[-1])], "criterion": j.criterion}
            if verdict is None:  # this run does not decide: this variant alone, on longer horizons
                v = step_verdict(loops[start + i], step[0], step[1], t_step, 2 * horizon, args.max_horizon,
                                 disturbances, sim.seed, sim.limit_cycle.min_amplitude, sim.limit_cycle.window)
                verdict, m = v.verdict, v.metrics
                evidence = v.evidence.to_dict()
                evidence["horizons"] = [float(res.t[-1]), *evidence["horizons"]]
            m = m if verdict == "settled" else unsettled(m)  # no step metrics for a step that does not settle
            entries.append({name: value, "verdict": verdict, "evidence": evidence, **m.to_dict()})
            series.setdefault("t", res.t)
            series[f"output_{name}={value:.6g}"] = res.output
            lc = m.limit_cycle
            rows.append([f"{value:.4g}", fmt(m.rise_time), fmt(m.overshoot),
                         fmt(m.settling_time) if m.settling_time is not None else "-",
                         fmt(m.rate_limited_time), fmt(m.saturated_time),
                         f"{fmt(lc.amplitude)} / {fmt(lc.period)} s" if verdict == "limit_cycle" else
                         {"diverging": "diverges", "settled": "none"}.get(verdict, "undetermined")])
        bar.update(len(batch))
    bar.close()
    payload = {"spec": spec.name, "controller": str(loop.controller), "parameter": name, "step": list(step),
               "step_time": t_step, "horizon": horizon, "loop": loop.to_dict(), "runs": entries}
    out_dir = Path(args.out) if args.out else Path("reports") / spec.name / "simulate"
    folder = OutputDir(out_dir, args.force) if not args.csv else None
    csv_path = _claim(Path(args.csv), args.force) if args.csv else folder.claim("sweep.csv")  # type: ignore[union-attr]
    _write_csv(csv_path, series, f"{GENERATOR}: {spec.name}, sweep of {name}, output of every run")
    if folder is not None:
        (folder.claim("sweep.json")).write_text(dump_json(payload), encoding="utf-8")
        folder.commit()
    if args.json == "-":
        sys.stdout.write(dump_json(to_jsonable(payload)))
    elif args.json:
        write_json(args.json, payload, force=args.force)
    say(f"{spec.name}: sweep of {name} over {len(values)} values, step {fmt(step[0])} -> {fmt(step[1])}")
    say(table([name, "rise [s]", "overshoot [%]", "settling [s]", "rate-limited [s]", "saturated [s]",
               "limit cycle (amplitude / period)"], rows))
    say(f"\ntime series: {folder.final(csv_path) if folder is not None else csv_path}")
    codes = {EXIT_CODES[e["verdict"]] for e in entries}
    return 1 if 1 in codes else (3 if 3 in codes else 0)
