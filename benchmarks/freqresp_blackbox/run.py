"""Black-box harness for ``synth freqresp``: random frequency-sweep problems against an exact response.

Written by a black-box tester who had not read synth's code; the reference (``reference.py``) uses
numpy/scipy only. From a seed, each problem draws a random plant and sweep (synth ``sweep-design`` or a
log chirp), simulates noisy records into CSV files, runs ``python -m synth freqresp ... --fit <true
structure> --json`` on them and compares the identified response with the exact one (and the fitted
parameters with the truth, as z-scores). Per problem the folder ``DIR/pNN`` keeps the records,
``cmd.sh``, the JSON and the output; all records go to ``DIR/results_<seed>.json``.

Run: ``python benchmarks/freqresp_blackbox/run.py --seed 556 --problems 44 --out DIR`` (2-3 minutes),
then ``python benchmarks/freqresp_blackbox/summarize.py DIR/results_556.json``.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

if __package__:
    from .reference import Plant, log_chirp, simulate
else:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from benchmarks.freqresp_blackbox.reference import Plant, log_chirp, simulate

ROOT = Path(__file__).resolve().parents[2]
SYN = ["python", "-m", "synth"]


def run(args):
    """Run ``python -m synth ARGS`` in the project root; return the completed process and the seconds."""
    t0 = time.time()
    r = subprocess.run(SYN + args, cwd=ROOT, capture_output=True, text=True)
    return r, time.time() - t0


def rand_plant(rng, allow_int=True, max_order=4, force=None):
    """A random plant: order 1-4, real poles and lightly or well damped quadratics, maybe a zero, delay, integrator."""
    order = int(rng.integers(1, max_order + 1))
    nint = 0
    if allow_int and rng.random() < 0.35:
        nint = 1
    rest = order - nint
    quads = []
    poles = []
    while rest > 0:
        if rest >= 2 and rng.random() < 0.55:
            wn = float(np.exp(rng.uniform(np.log(0.8), np.log(15))))
            zeta = float(rng.uniform(0.05, 0.3) if rng.random() < 0.6 else rng.uniform(0.3, 0.9))
            quads.append((round(2 * zeta * wn, 4), round(wn * wn, 4)))
            rest -= 2
        else:
            poles.append(round(float(np.exp(rng.uniform(np.log(0.3), np.log(25)))), 4))
            rest -= 1
    zeros = []
    if rng.random() < 0.4 and order >= 2:
        zeros.append(round(float(np.exp(rng.uniform(np.log(0.5), np.log(20)))), 4))
    Td = round(float(rng.uniform(0, 0.1)), 4) if rng.random() < 0.6 else 0.0
    # gain: normalise so the mid-band gain is O(1) times a random factor
    p = Plant(1.0, zeros, poles, quads, nint, Td)
    g = abs(p.H([1.0])[0])
    k = round(float(np.exp(rng.uniform(-1.5, 1.5)) / g), 5)
    return Plant(k, zeros, poles, quads, nint, Td)


def formula_fit(pl):
    """The true structure as a formula with named parameters, and the truth dict."""
    truth = {"k": pl.k}
    num = "k"
    for j, z in enumerate(pl.zeros):
        num += f"*(s+z{j + 1})"
        truth[f"z{j + 1}"] = z
    dens = ["s"] * pl.nint
    for j, p in enumerate(pl.poles):
        dens.append(f"(s+p{j + 1})")
        truth[f"p{j + 1}"] = p
    for j, (a, b) in enumerate(pl.quads):
        dens.append(f"(s^2+a{j + 1}*s+b{j + 1})")
        truth[f"a{j + 1}"] = a
        truth[f"b{j + 1}"] = b
    f = num + "/(" + "*".join(dens) + ")"
    if pl.Td > 0:
        f += "*exp(-Td*s)"
        truth["Td"] = pl.Td
    else:
        truth["delay"] = 0.0
    return f, truth


def make_problem(rng, i, outdir, plant=None, noise_seed=None, force=None):
    """Draw problem i (plant, sweep, noise), write its records to outdir; return (plant, info) or None."""
    force = force or {}
    pl = plant or rand_plant(rng, allow_int=rng.random() < 0.15)
    fs = float(force.get("fs", rng.choice([50, 100, 200, 250, 500, 1000])))
    nruns = int(force.get("nruns", rng.choice([1, 1, 2, 3])))
    T = float(force.get("T", round(float(np.exp(rng.uniform(np.log(30), np.log(300)))), 1)))
    Ttot = T * nruns
    wlo = max(0.1, 12 * np.pi * 1.3 / Ttot, 2 * 2 * np.pi / T * 0.5)
    w0 = float(force.get("w0", np.exp(rng.uniform(np.log(wlo), np.log(max(wlo * 1.01, 1.2))))))
    w1 = float(force.get("w1", min(np.exp(rng.uniform(np.log(8), np.log(40))), 0.2 * np.pi * fs * 0.9)))
    snr = force.get("snr", None if rng.random() < 0.2 else float(rng.uniform(10, 40)))
    kind = force.get("kind", "design" if rng.random() < 0.35 else "chirp")
    A = float(np.exp(rng.uniform(-1, 1)))
    trim = float(rng.uniform(-5, 5))
    nrng = np.random.default_rng(noise_seed if noise_seed is not None else 1000 + i)
    os.makedirs(outdir, exist_ok=True)
    files = []
    if kind == "design":
        f = os.path.join(outdir, "design.csv")
        r, _ = run(["sweep-design", "--w-min", f"{w0:.6g}", "--w-max", f"{w1:.6g}", "--duration", f"{T:.6g}",
                    "--sample-rate", f"{fs:g}", "--amplitude", f"{A:.6g}", "--out", f, "--force"])
        if r.returncode != 0:
            print("sweep-design failed", r.stdout, r.stderr)
            return None
        dd = np.loadtxt(f, delimiter=",", skiprows=2)
        t = dd[:, 0]
        u = dd[:, 1]
        ufun = None
    else:
        t = np.arange(0, T, 1 / fs)
        fade = min(2 * np.pi / w0 / 4, T / 10)

        def ufun(tt):
            return log_chirp(tt, w0, w1 * 1.15, T, A, fade)

        u = ufun(t)
    y0 = simulate(pl, t, u, ufun)
    rms = np.std(y0)
    for rr in range(nruns):
        y = y0 + trim
        if snr is not None:
            y = y + rms * 10 ** (-snr / 20) * nrng.standard_normal(len(y))
        fn = os.path.join(outdir, f"run{rr}.csv")
        np.savetxt(fn, np.c_[t, u + 0.0, y], delimiter=",", header="t,u,y", comments="", fmt="%.9g")
        files.append(fn)
    info = dict(i=i, formula=pl.formula(), Td=pl.Td, nint=pl.nint, fs=fs, nruns=nruns, T=T, w0=w0, w1=w1, snr=snr,
                kind=kind, A=A, trim=trim, files=files)
    return pl, info


def check_response(pl, d):
    """Compare synth's response JSON d with the exact response over the coherent band (errors, z-scores)."""
    w = np.array(d["w"])
    m = np.array(d["magnitude_db"])
    p = np.array(d["phase_deg"])
    e = np.array(d["random_error"]) if d.get("random_error") else None
    b = d["coherent_band"]
    ib = (w >= b["w_min"] * (1 - 1e-9)) & (w <= b["w_max"] * (1 + 1e-9))
    tm = pl.mag_db(w)
    tp = pl.phase_deg(w)
    dm = m - tm
    dpr = p - tp
    dp = (dpr + 180) % 360 - 180
    offs = np.round((dpr - dp) / 360)
    res = dict(n=int(ib.sum()), band=(b["w_min"], b["w_max"]), max_dm=float(np.max(np.abs(dm[ib]))),
               max_dp=float(np.max(np.abs(dp[ib]))), med_dm=float(np.median(np.abs(dm[ib]))),
               med_dp=float(np.median(np.abs(dp[ib]))), phase_wrap_offsets=sorted(set(offs[ib].astype(int).tolist())))
    if e is not None:
        zm = dm / (20 / np.log(10) * e)
        zp = np.radians(dp) / e
        res.update(cov_m=float(np.mean(np.abs(zm[ib]) < 2)), cov_p=float(np.mean(np.abs(zp[ib]) < 2)),
                   max_zm=float(np.max(np.abs(zm[ib]))), max_zp=float(np.max(np.abs(zp[ib]))),
                   worst_w=float(w[ib][np.argmax(np.abs(zm[ib]) + np.abs(zp[ib]))]))
        res["z"] = (w[ib].tolist(), zm[ib].tolist(), zp[ib].tolist(), dm[ib].tolist(), dp[ib].tolist(), e[ib].tolist())
    return res


def _load(path):
    with open(path) as fh:
        return json.load(fh)


def _data_args(files):
    return [a for x in files for a in ("--data", x)]


def main(argv=None):
    """Run the problems and write DIR/results_<seed>.json."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=555)
    ap.add_argument("--problems", type=int, default=44)
    ap.add_argument("--out", default=None, help="working/output folder (default: a fresh temporary folder)")
    a = ap.parse_args(argv)
    out_dir = Path(a.out) if a.out else Path(tempfile.mkdtemp(prefix="freqresp_blackbox_"))
    out_dir.mkdir(parents=True, exist_ok=True)
    seed = a.seed
    N = a.problems
    rng = np.random.default_rng(seed)
    allres = []
    for i in range(N):
        pdir = str(out_dir / f"p{i:02d}")
        out = make_problem(rng, i, pdir)
        if out is None:
            continue
        pl, info = out
        f, truth = formula_fit(pl)
        args = ["freqresp", *_data_args(info["files"]), "--fit", f, "--json", pdir + "/res.json", "--force"]
        Path(pdir + "/cmd.sh").write_text(f"cd {ROOT} && python -m synth " + " ".join(f"'{x}'" for x in args) + "\n")
        r, dt = run(args)
        Path(pdir + "/stdout.txt").write_text(r.stdout + "\n---stderr---\n" + r.stderr)
        rec = dict(info=info, truth=truth, fit_formula=f, rc=r.returncode, secs=dt, stdout=r.stdout, stderr=r.stderr)
        if "Traceback" in r.stderr:
            print("TRACEBACK", i)
        if r.returncode == 0 and os.path.exists(pdir + "/res.json"):
            d = _load(pdir + "/res.json")
            rec["resp"] = check_response(pl, d)
            fit = d.get("fit")
            if fit:
                P = fit["parameters"]
                U = fit.get("uncertainty") or {}
                S = U.get("std", {})
                zs = {}
                for k, v in truth.items():
                    kk = k if k in P else ("delay" if k in ("Td", "delay") and "delay" in P else k)
                    if kk in P and isinstance(S.get(kk), (int, float)) and S.get(kk) != 0:
                        zs[k] = (P[kk], S[kk], (P[kk] - v) / S[kk])
                    elif kk in P:
                        zs[k] = (P[kk], S.get(kk), None)
                rec["fit"] = dict(z=zs, weak=U.get("weak"), rho=U.get("residual_correlation"),
                                  fit_percent=fit.get("fit_percent"), J=fit.get("J"), w_range=fit.get("w_range"),
                                  at_bound=U.get("at_bound"))
        elif r.returncode == 1:
            # fit failed? rerun without fit for the response
            args2 = ["freqresp", *_data_args(info["files"]), "--json", pdir + "/res_nofit.json", "--force"]
            r2, _ = run(args2)
            rec["rc_nofit"] = r2.returncode
            if r2.returncode == 0:
                rec["resp"] = check_response(pl, _load(pdir + "/res_nofit.json"))
        allres.append(rec)
        R = rec.get("resp", {})
        F = rec.get("fit", {})
        snr = info["snr"] and round(info["snr"], 1)
        print(f"{i:2d} {info['formula']} Td={pl.Td:.3g} fs={info['fs']:g} runs={info['nruns']:d} T={info['T']:g} "
              f"w={info['w0']:.2f}-{info['w1']:.1f} snr={snr} {info['kind']} rc={r.returncode:d} {dt:.1f}s")
        if R:
            print(f"    band {R['band'][0]:.3g}-{R['band'][1]:.3g} n={R['n']:d}  |dm| med {R['med_dm']:.3f} "
                  f"max {R['max_dm']:.3f} dB, |dp| med {R['med_dp']:.2f} max {R['max_dp']:.2f} deg; "
                  f"cov_m {R.get('cov_m', -1):.2f} cov_p {R.get('cov_p', -1):.2f} "
                  f"maxz {R.get('max_zm', -1):.1f}/{R.get('max_zp', -1):.1f} @{R.get('worst_w', -1):.3g} "
                  f"wraps {R['phase_wrap_offsets']}")
        if F:
            zs_txt = " ".join(f"{k}={f'{v[2]:.2f}' if v[2] is not None else 'NA'}" for k, v in F["z"].items())
            print(f"    fit {F['fit_percent'] or -1:.1f}% rho={F['rho'] or -1:.2f} weak={F['weak']}  z: {zs_txt}")
        if r.returncode != 0:
            print("    OUT:", r.stdout.strip().splitlines()[-1:], r.stderr[-300:])
        sys.stdout.flush()
    res_path = out_dir / f"results_{seed}.json"
    with open(res_path, "w") as fh:
        json.dump(allres, fh, default=str)
    print(f"results: {res_path}")


if __name__ == "__main__":
    main()
