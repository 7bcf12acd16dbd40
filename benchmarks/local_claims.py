"""How often a stored design's "local optimum" claim fails the first-order test on the exact requirements.

For every record of ``benchmarks/design_verification.py`` whose design is feasible and whose verdict claims a local
optimum, :func:`synth.synthesis.ascent_probe.climb` runs from the stored parameters. A climb is a design that passes
synth's exact check and scores at least 0.1 % better per step; each climbed point is also checked by the
independent reference (``benchmarks/design_reference.py``'s dense check).

Run: ``python benchmarks/local_claims.py reports/design_verification/seed2*_s*.jsonl``
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.design_reference import check_point
from synth.controllers import Controller
from synth.loop import Loop
from synth.objectives import score
from synth.spec import parse_spec
from synth.synthesis.ascent_probe import climb
from synth.synthesis.integral_action import objective_terms


def main(files: list[str]) -> int:
    claims, rows, seen = 0, [], set()
    start = time.process_time()
    for name in files:
        for line in Path(name).read_text(encoding="utf-8").splitlines():
            r = json.loads(line)
            if r.get("synth_status") != "feasible" or not (r.get("synth_optimality") or {}).get("local"):
                continue
            key = json.dumps([r["spec"], r["synth_params"]], sort_keys=True)
            if key in seen:  # the same problem and design in two record files
                continue
            seen.add(key)
            claims += 1
            spec = parse_spec(r["spec"])
            terms, nominal = objective_terms(spec), spec.nominal_plant()
            design = Controller(spec.controller.type, r["synth_params"])
            top, steps = climb(spec, design, terms, 0.05)
            if steps:
                before, after = score(Loop(nominal, design), terms), score(Loop(nominal, top), terms)
                ref = check_point(r["num"], r["den"], r["delay"], r["spec"], top.parameters)
                rows.append((Path(name).name, r["index"], r["controller"], steps,
                             (after - before) / max(abs(before), 1e-12), ref.feasible(1e-3)))
    print(f"designs claiming a local optimum: {claims}; climbed: {len(rows)}; CPU {time.process_time() - start:.1f} s")
    print("\n| record | problem | controller | steps | objective gain | the reference's check |\n|---|---|---|---|---|---|")
    for f, i, c, n, gain, ok in rows:
        print(f"| {f} | #{i} | {c} | {n} | {100 * gain:.2f} % | {'passes' if ok else 'FAILS'} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
