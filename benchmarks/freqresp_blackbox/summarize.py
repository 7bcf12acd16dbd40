"""Summary of a freqresp black-box results JSON (written by ``run.py``).

Part of an independent check written by a black-box tester who had not read synth's code (numpy/scipy
only). For the lowest fifth, the middle and the top fifth of each problem's coherent band (log scale),
it prints the share of points within 2 random errors in magnitude and phase, the share with errors
above 1 dB or 5 deg and the median errors; then the problems with points both large (> 1 dB or
> 6 deg) and significant (> 3 random errors).

Run: ``python benchmarks/freqresp_blackbox/summarize.py DIR/results_<seed>.json``.
"""

import json
import sys

import numpy as np


def summarize(R):
    """Print the summary lines for the list of result records R."""
    reg = {"low": [], "mid": [], "top": []}
    big = []
    for r in R:
        z = r.get("resp", {}).get("z")
        if not z:
            continue
        w, zm, zp, dm, dp, _e = map(np.array, z)
        lo, hi = np.log10(w.min()), np.log10(w.max())
        x = (np.log10(w) - lo) / max(hi - lo, 1e-9)
        for name, m in [("low", x < 0.2), ("mid", (x >= 0.2) & (x <= 0.8)), ("top", x > 0.8)]:
            reg[name] += list(zip(zm[m], zp[m], dm[m], dp[m]))
        bad = (np.abs(dm) > 1) | (np.abs(dp) > 6)
        sig = (np.abs(zm) > 3) | (np.abs(zp) > 3)
        if np.any(bad & sig):
            big.append((r["info"]["i"], r["info"]["kind"], r["info"]["snr"], int(np.sum(bad & sig)), len(w),
                        float(np.max(np.abs(dm))), float(np.max(np.abs(dp)))))
    for k, v in reg.items():
        v = np.array(v)
        fin = np.isfinite(v[:, 0]) & np.isfinite(v[:, 1])
        print(f"{k}: {len(v):d} pts, |zm|<2 {np.mean(np.abs(v[fin, 0]) < 2):.2f} "
              f"|zp|<2 {np.mean(np.abs(v[fin, 1]) < 2):.2f}; "
              f"|dm|>1dB {np.mean(np.abs(v[:, 2]) > 1):.3f} |dp|>5deg {np.mean(np.abs(v[:, 3]) > 5):.3f}; "
              f"median|dm| {np.median(np.abs(v[:, 2])):.3f} dB median|dp| {np.median(np.abs(v[:, 3])):.2f} deg")
    allv = np.concatenate([np.array(v) for v in reg.values()])
    fin = np.isfinite(allv[:, 0]) & np.isfinite(allv[:, 1])
    print(f"ALL: {len(allv):d} pts |zm|<2 {np.mean(np.abs(allv[fin, 0]) < 2):.3f} "
          f"|zp|<2 {np.mean(np.abs(allv[fin, 1]) < 2):.3f} ; eps==0 points: {int(np.sum(~fin)):d}")
    print("problems with points >1 dB or >6 deg AND >3 random errors off (i,kind,snr,npts,n,max|dm|,max|dp|):")
    for b in big:
        print("  ", b)


def main(argv=None):
    """Summarize the results JSON named on the command line."""
    argv = sys.argv[1:] if argv is None else argv
    with open(argv[0]) as fh:
        summarize(json.load(fh))


if __name__ == "__main__":
    main()
