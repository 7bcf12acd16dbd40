"""Speed of ``synth diagnose`` against record length, with the previous version's time in the same run.

Cases: the X-4 rotor drive (eq. 5, ``23 (s+0.43)/((s+9.6)(s+0.54))``, PWM -> rad/s, sampled at 0.02 s,
noise 1 rad/s). The nominal handed to the diagnosis has every coefficient off by 5 % (fixed random
signs). The input is a step train: levels drawn in 150-250 PWM (the first 200), each held 1.5-4 s. One effect is
withheld (a dead zone, a delay, a drift, a backlash or a rate limit, each several times the noise). The
estimation record has ``n`` samples, the validation record (another step train, same plant and effect)
``0.8 n`` samples, as in issue 17 (20,000 + 16,000). One diagnosis (:func:`synth.gap.diagnose.diagnose`:
localization and attribution with every default candidate, 2 worker processes) per record. With ``--input smooth``
the command varies continuously instead (white noise low-passed at 0.5 Hz, scaled to 150-250 PWM about 200, as a
closed loop's command is): thousands of distinct values, which the quantizer's dense search cannot reduce to a
few levels.

Each diagnosis runs in a fresh process (``--one``; the time is the diagnosis alone, without imports): wall
time, and CPU time of the process and its worker processes (on a loaded machine the CPU time is the
comparable number; on an idle 2-core machine the wall time lies between half of it and all of it). The
baseline is the same script run in a ``git worktree`` of ``--baseline-ref`` (default: ``HEAD``), in a
temporary folder, right after this version's run of the same case, so both columns see the same load.

How time grows: for each pair of consecutive sizes, the ratio of each effect's time (summed over ``--seeds``
records) and of the total over the effects, beside the ratio of the sample counts. One record per size is a noisy
measure of growth: which candidates the screen carries into the joint re-fit differs from record to record (a
supply-sag candidate costs several times a quantizer's), so ``--seeds`` draws several records of each size.

Run:  python benchmarks/gap/diagnose_speed.py [--sizes 2000 20000 100000 1000000] [--effects ...] [--seeds 1]
      [--baseline-ref REF | --no-baseline] [--timeout 600] [--baseline-max 100000] [--jobs 1]
      [--input steps|smooth]
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as `import synth` sets it (numpy is imported first here)
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from synth.data import record_from_arrays  # noqa: E402
from synth.data.record import Record  # noqa: E402
from synth.gap.effects import make_effect  # noqa: E402
from synth.plant import Plant  # noqa: E402

TRUE = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
DT = 0.02
NOISE = 1.0
EFFECTS: dict[str, dict[str, float]] = {
    "deadzone": {"width": 25.0, "center": 200.0},
    "delay": {"delay": 0.12},
    "drift": {"slope": 0.0},  # set to 3 rad/s over the record
    "backlash": {"width": 12.0},
    "rate_limit": {"rate": 60.0},
}


def nominal(seed: int = 0) -> Plant:
    """The true plant with every coefficient off by 5 % (random signs)."""
    rng = np.random.default_rng(seed)
    num = TRUE.num * (1.0 + 0.05 * rng.choice([-1.0, 1.0], TRUE.num.size))
    den = TRUE.den.copy()
    den[1:] *= 1.0 + 0.05 * rng.choice([-1.0, 1.0], den.size - 1)
    return Plant(num, den)


def step_train(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``n`` samples of a step train: levels in 150-250 PWM held 1.5-4 s each."""
    t = np.arange(n) * DT
    holds = rng.uniform(1.5, 4.0, size=int(n * DT / 1.5) + 2)
    edges = np.concatenate([[0.0], np.cumsum(holds)])
    levels = rng.uniform(150.0, 250.0, size=edges.size)
    levels[0] = 200.0  # the dead zone's center: the command at rest
    return t, levels[np.searchsorted(edges, t, side="right") - 1]


def smooth_command(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``n`` samples of a continuously varying command: white noise through a first-order low-pass at 0.5 Hz
    (exact discretization), scaled to 150-250 PWM about 200."""
    from scipy.signal import lfilter

    a = np.exp(-2.0 * np.pi * 0.5 * DT)
    x = lfilter([1.0 - a], [1.0, -a], rng.normal(size=n))
    return np.arange(n) * DT, 200.0 + 50.0 * x / np.max(np.abs(x))


def case(effect: str, n: int, seed: int = 0, kind: str = "steps") -> tuple[Record, Record]:
    """The estimation record (``n`` samples) and the validation record (``0.8 n``) with ``effect`` withheld;
    ``kind`` is the command (``"steps"``: :func:`step_train`, ``"smooth"``: :func:`smooth_command`)."""
    rng = np.random.default_rng([seed, n, list(EFFECTS).index(effect)])
    out = []
    for m in (n, int(0.8 * n)):
        t, u = (smooth_command if kind == "smooth" else step_train)(m, rng)
        params = dict(EFFECTS[effect])
        if effect == "drift":
            params["slope"] = 3.0 / float(t[-1])
        y = make_effect(effect).apply(TRUE, t, u, params) + NOISE * rng.normal(size=m)
        out.append(record_from_arrays(t, u, y))
    return out[0], out[1]


def run_one(effect: str, n: int, workers: int = 2, seed: int = 0, kind: str = "steps") -> dict[str, object]:
    """Time one diagnosis of the ``effect`` case of ``n`` samples, record ``seed`` (this checkout's code)."""
    import resource

    from synth.gap.diagnose import diagnose

    def cpu() -> float:  # this process and its reaped children (the pool's workers)
        return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                      resource.getrusage(resource.RUSAGE_CHILDREN)))

    rec, val = case(effect, n, seed, kind)
    t0, c0 = time.perf_counter(), cpu()
    fd = os.dup(2)
    try:  # casadi writes its warnings to file descriptor 2
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
            dg = diagnose(nominal(), rec, val, workers=workers)
    finally:
        os.dup2(fd, 2)
        os.close(fd)
    return {"seconds": time.perf_counter() - t0, "cpu": cpu() - c0, "verdict": list(dg.verdict["effects"])}


def timed(tree: Path, effect: str, n: int, timeout: float, seed: int = 0, kind: str = "steps") -> dict[str, object]:
    """One diagnosis by the code in ``tree`` (this checkout or the baseline worktree), in a fresh process.

    ``seconds`` is the diagnosis alone (no imports, no record generation); ``None`` when it did not finish
    within ``timeout`` seconds or failed (``verdict`` then says which).
    """
    cmd = [sys.executable, str(tree / "benchmarks/gap/diagnose_speed.py"), "--one", effect, str(n), str(seed), kind]
    env = dict(os.environ, PYTHONPATH=str(tree))
    try:
        out = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return {"seconds": None, "verdict": [f"not done in {timeout:.0f} s"]}
    if out.returncode != 0:
        return {"seconds": None, "verdict": [f"failed: {' '.join(out.stderr.strip().splitlines()[-1:])}"]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> None:
    """CLI."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[2000, 20000, 100000, 1000000])
    ap.add_argument("--effects", nargs="+", default=list(EFFECTS), choices=list(EFFECTS))
    ap.add_argument("--baseline-ref", default="HEAD")
    ap.add_argument("--no-baseline", action="store_true")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds one diagnosis may take (each version)")
    ap.add_argument("--baseline-max", type=int, default=100000, help="largest size the baseline is run at")
    ap.add_argument("--jobs", type=int, default=1, help="diagnoses run at once (compare CPU times then)")
    ap.add_argument("--seeds", type=int, default=1, help="records per effect and size")
    ap.add_argument("--input", choices=["steps", "smooth"], default="steps", help="the command: a step train or "
                    "a continuously varying (closed-loop-like) command")
    ap.add_argument("--one", nargs=4, metavar=("EFFECT", "N", "SEED", "INPUT"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.one:
        print(json.dumps(run_one(args.one[0], int(args.one[1]), seed=int(args.one[2]), kind=args.one[3])))
        return
    tmp = None
    if not args.no_baseline:
        tmp = tempfile.TemporaryDirectory(prefix="synth-baseline-")
        tree = Path(tmp.name) / "tree"
        subprocess.run(["git", "worktree", "add", "--detach", str(tree), args.baseline_ref], cwd=ROOT, check=True,
                       capture_output=True)
        # the same cases and timing in both trees: this script runs there too (only `synth` differs)
        (tree / "benchmarks/gap/diagnose_speed.py").write_text(Path(__file__).read_text())
    tasks = [(where, effect, n, seed) for n in args.sizes for effect in args.effects for seed in range(args.seeds)
             for where in ("new", *(("old",) if tmp is not None and n <= args.baseline_max else ()))]
    results: dict[tuple[str, str, int, int], dict[str, object]] = {}

    def work(task: tuple[str, str, int, int]) -> None:
        where, effect, n, seed = task
        results[task] = timed(ROOT if where == "new" else tree, effect, n, args.timeout, seed, args.input)
        print(f"{where} {effect} {n} #{seed}: {results[task]}", file=sys.stderr, flush=True)

    try:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(args.jobs) as pool:
            list(pool.map(work, tasks))
        rows = [(effect, n, results[("new", effect, n, seed)], results.get(("old", effect, n, seed)), seed)
                for n in args.sizes for effect in args.effects for seed in range(args.seeds)]
    finally:
        if tmp is not None:
            subprocess.run(["git", "worktree", "remove", "--force", str(tree)], cwd=ROOT, check=False,
                           capture_output=True)
            tmp.cleanup()

    def cell(res: dict[str, object] | None) -> tuple[str, str, str]:
        if res is None:
            return "-", "-", "-"
        secs, cpu = res["seconds"], res.get("cpu")
        return (("n/a" if secs is None else f"{secs:.1f}"), ("n/a" if cpu is None else f"{cpu:.1f}"),
                ", ".join(res["verdict"]) or "(none)")

    ref = "" if args.no_baseline else f" ({args.baseline_ref})"
    print(f"| samples (+0.8 n validation) | effect | record | wall [s] | CPU [s] | verdict | baseline{ref} wall [s] | "
          "baseline CPU [s] | baseline verdict |")
    print("|---|---|---|---|---|---|---|---|---|")
    for effect, n, new, old, seed in rows:
        print(f"| {n} | {effect} | {seed} | {' | '.join(cell(new))} | {' | '.join(cell(old))} |")
    print_growth(rows, args.sizes, args.effects)
    for n in args.sizes:
        for label, k in (("this version", 2), ("baseline", 3)):
            for what in ("seconds", "cpu"):
                ts = [np.inf if r[k].get(what) is None else r[k][what] for r in rows if r[1] == n and r[k] is not None]
                if ts:  # a run that did not finish counts as longer than the timeout
                    med, worst = (f"{x:.1f} s" if np.isfinite(x) else "not done" for x in (np.median(ts), max(ts)))
                    print(f"{n} samples, {label}, {'wall' if what == 'seconds' else 'CPU'}: median {med}, "
                          f"worst {worst} ({len(ts)} records)")


def print_growth(rows: list[tuple], sizes: list[int], effects: list[str]) -> None:
    """Ratio of CPU times between consecutive sizes, per effect (summed over its records) and in total."""
    sizes = sorted(sizes)
    for a, b in itertools.pairwise(sizes):
        per = {}
        for eff in effects:
            ta = [r[2].get("cpu") for r in rows if r[0] == eff and r[1] == a]
            tb = [r[2].get("cpu") for r in rows if r[0] == eff and r[1] == b]
            if ta and tb and None not in ta + tb:
                per[eff] = (sum(ta), sum(tb))
        if not per:
            continue
        total = sum(x[1] for x in per.values()) / sum(x[0] for x in per.values())
        cells = ", ".join(f"{eff} {tb / ta:.1f}x" for eff, (ta, tb) in per.items())
        print(f"CPU time from {a} to {b} samples ({b / a:.0f}x the samples): {cells}; all effects {total:.1f}x")


if __name__ == "__main__":
    main()
