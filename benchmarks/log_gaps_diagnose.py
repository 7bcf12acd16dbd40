"""``diagnose`` on step records whose log drops out over edges: the verdict against the truth, over random cases.

Each case (``numpy.random.default_rng(case)``): a first- or second-order plant, a train of random levels (0.8-3 s
holds, 20-40 of them, the first at rest) logged every 10 ms, and three dropouts of 0.3-0.6 s, each hiding an edge.
The truth is the nominal plant alone, the plant behind a whole-sample delay of 30-80 ms, or behind an extra lag of
30-80 ms; it is simulated by ``scipy.signal.cont2discrete`` (zero-order hold, exact for a held command) and
``scipy.signal.lfilter``, independent of synth, with white output noise of 1 % of the output's spread. Each record
goes through ``synth.gap.diagnose.diagnose`` with the nominal plant, the candidates ``delay`` and ``lag``, and
``n_null=3``; the same record without its dropouts is the reference of what the data can show.

A verdict is right when it names the truth's effect and nothing else (the nominal plant alone: no effect), a named
delay or lag within 25 % of the truth (a lag: of the extra lag, or of a second-order plant's other time constant,
which the diagnosis's refit may trade with it: the two give the same model).

Run (from the repository root; ``PYTHONPATH`` picks the synth to measure):

    python benchmarks/log_gaps_diagnose.py --cases 60
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings

import numpy as np
from scipy import signal

TRUTHS = ("none", "delay", "lag")
DT = 0.01


def case_record(case: int) -> dict:
    """One case: the nominal plant's string, the truth, and ``(t, u, y)`` with and without the dropouts."""
    rng = np.random.default_rng(case)
    second = bool(rng.integers(0, 2))
    k, t1 = float(rng.uniform(0.5, 4.0)), float(rng.uniform(0.08, 0.4))
    t2 = float(rng.uniform(0.02, 0.3 * t1)) if second else 0.0
    holds = rng.uniform(0.8, 3.0, size=int(rng.integers(20, 41)))
    edges = np.concatenate([[0.0], np.cumsum(holds)])
    levels = np.concatenate([[0.0], rng.uniform(-1.0, 1.0, size=holds.size - 1)]) * float(rng.uniform(1.0, 10.0))
    t = np.arange(0.0, edges[-1], DT)
    u = levels[np.minimum(np.searchsorted(edges, t, side="right") - 1, levels.size - 1)]
    truth = TRUTHS[case % 3]
    den = np.polymul([t1, 1.0], [t2, 1.0]) if second else np.array([t1, 1.0])
    shift, extra = 0, 0.0
    if truth == "delay":
        shift = int(rng.integers(3, 9))
    elif truth == "lag":
        extra = float(rng.uniform(0.03, 0.08))
    num, dd, _ = signal.cont2discrete(([k], np.polymul(den, [extra, 1.0])), DT, method="zoh")
    y = signal.lfilter(np.ravel(num), dd, np.r_[np.zeros(shift), u[: u.size - shift]])
    y = y + 0.01 * float(np.std(y)) * np.random.default_rng(10_000 + case).standard_normal(t.size)
    keep = np.ones(t.size, bool)
    inner = edges[3:-3]
    for edge in rng.choice(inner, size=min(3, inner.size), replace=False):
        length = float(rng.uniform(0.3, 0.6))
        start = edge - float(rng.uniform(0.05, length - 0.05))
        keep &= (t <= start) | (t >= start + length)
    nominal = f"{k}/(({t1}*s+1)*({t2}*s+1))" if second else f"{k}/({t1}*s+1)"
    values = {"none": [0.0], "delay": [shift * DT], "lag": [extra, *([t2] if second else [])]}[truth]
    return {"nominal": nominal, "truth": truth, "values": values, "full": (t, u, y),
            "logged": (t[keep], u[keep], y[keep])}


def judged(d: dict, truth: str, values: list[float]) -> bool:
    """Whether a diagnosis names the truth's effect and nothing else, its parameter within 25 % of one of
    ``values``."""
    named = d["verdict"]["effects"]
    if truth == "none":
        return not named
    if named != [truth]:
        return False
    found = next(e for e in d["effects"] if e["effect"] == truth)["parameters"]
    return any(abs(float(next(iter(found.values()))) - v) <= 0.25 * v for v in values)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=60)
    parser.add_argument("--json", help="write the rows as JSON lines")
    args = parser.parse_args()
    from synth.data import record_from_arrays
    from synth.gap.diagnose import diagnose
    from synth.plant import Plant

    rows = []
    for case in range(args.cases):
        c = case_record(case)
        row = {"case": case, "truth": c["truth"], "values": c["values"]}
        for variant in ("full", "logged"):
            rec = record_from_arrays(*c[variant])
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                d = diagnose(Plant.from_string(c["nominal"]), rec, candidates=["delay", "lag"], n_null=3).to_dict()
            row[variant] = {"right": judged(d, c["truth"], c["values"]), "effects": d["verdict"]["effects"],
                            "status": d["verdict"]["status"], "nrmse": d["gap"]["nrmse"], "gaps": len(rec.gaps),
                            "seconds": time.perf_counter() - t0, "samples": rec.n}
        rows.append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)
    if args.json:
        with open(args.json, "w") as fh:
            fh.writelines(json.dumps(r) + "\n" for r in rows)
    print("| truth | cases | right without the dropouts | right with them | median NRMSE without / with |")
    print("|---|---|---|---|---|")
    for truth in (*TRUTHS, "all"):
        sel = [r for r in rows if truth in ("all", r["truth"])]
        if not sel:
            continue
        full = sum(r["full"]["right"] for r in sel)
        logged = sum(r["logged"]["right"] for r in sel)
        nr = [np.median([r[v]["nrmse"] for r in sel]) for v in ("full", "logged")]
        print(f"| {truth} | {len(sel)} | {full} ({100 * full / len(sel):.1f} %) | {logged} ({100 * logged / len(sel):.1f} %)"
              f" | {nr[0]:.4f} / {nr[1]:.4f} |")
    samples = [r["logged"]["samples"] for r in rows]
    seconds = [r["logged"]["seconds"] for r in rows]
    print(f"\nrecords of {min(samples)}-{max(samples)} samples; diagnose with the dropouts: median "
          f"{np.median(seconds):.2f} s, max {max(seconds):.2f} s")


if __name__ == "__main__":
    main()
