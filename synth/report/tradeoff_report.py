"""Trade-off report: ``tradeoff.csv``, ``tradeoff.json``, ``tradeoff.html`` and ``tradeoff.png``."""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synth.figure_files import save_figure
from synth.outputs import GENERATOR, OutputDir, dump_json
from synth.report.figures import COLORS, plt
from synth.report.templating import render, reproducible
from synth.requirements.base import fmt
from synth.synthesis.tradeoff import TradeoffResult

__all__ = ["TradeoffFiles", "tradeoff_csv", "tradeoff_figure", "write_tradeoff_report"]


@dataclass
class TradeoffFiles:
    """Paths written by :func:`write_tradeoff_report`."""

    folder: Path
    csv: Path
    json: Path
    html: Path
    png: Path


def tradeoff_csv(result: TradeoffResult) -> str:
    """One row per point: swept values, feasible, objective, controller parameters, binding requirements,
    every requirement's slack.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> from synth.synthesis.tradeoff import Sweep, tradeoff
    >>> r = tradeoff(load_spec("specs/x4_rotor.yaml"), [Sweep.parse("requirements.bandwidth.min=60:60:1")], workers=1)
    >>> tradeoff_csv(r).splitlines()[0].split(",")[:4]
    ['requirements.bandwidth.min', 'feasible', 'objective', 'pareto']
    """
    params = sorted({k for p in result.points if p.controller for k in p.controller})
    slack_names = list(dict.fromkeys(k for p in result.points for k in p.slacks))
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow([s.path for s in result.sweeps] + ["feasible", "objective", "pareto"] + params
                    + ["binding"] + [f"slack:{n}" for n in slack_names])
    for p in result.points:
        writer.writerow([f"{p.values[s.path]:.10g}" for s in result.sweeps]
                        + [p.feasible, "" if p.objective is None else f"{p.objective:.10g}", p.pareto]
                        + [f"{p.controller[k]:.10g}" if p.controller else "" for k in params]
                        + [";".join(p.binding)]
                        + [f"{p.slacks[n]:.6g}" if n in p.slacks else "" for n in slack_names])
    return buf.getvalue()


def tradeoff_figure(result: TradeoffResult, path: Path) -> Path:
    """Objective against the swept value (one sweep) or a map over two, binding requirement by colour."""
    sweeps = result.sweeps
    name = result.objective["description"]
    binders = list(dict.fromkeys(p.binding[0] if p.binding else "none" for p in result.points))
    color = {b: COLORS[i % len(COLORS)] for i, b in enumerate(binders)}
    fig, ax = plt.subplots(figsize=(8, 4.6))
    if len(sweeps) == 1:
        path_ = sweeps[0].path
        feas = [p for p in result.points if p.feasible and p.objective is not None]
        xs = [p.values[path_] for p in feas]
        ys = [p.objective for p in feas]
        ax.plot(xs, ys, color="grey", lw=1, zorder=1)
        for b in binders:
            sel = [p for p in feas if (p.binding[0] if p.binding else "none") == b]
            ax.scatter([p.values[path_] for p in sel], [p.objective for p in sel], color=color[b], s=40, zorder=2,
                       label=f"binding: {b}")
        front = [p for p in feas if p.pareto]
        ax.scatter([p.values[path_] for p in front], [p.objective for p in front], facecolors="none",
                   edgecolors="black", s=140, lw=1.5, zorder=3, label="Pareto front")
        bad = [p for p in result.points if not p.feasible]
        if bad:
            y0 = min(ys) if ys else 0.0
            ax.scatter([p.values[path_] for p in bad], [y0] * len(bad), marker="x", color="#c0392b", s=60,
                       label="infeasible")
        ax.set_xlabel(path_)
        ax.set_ylabel(name)
    else:
        a, b = sweeps
        Z = np.full((len(a.values), len(b.values)), np.nan)
        for p in result.points:
            i, j = a.values.index(p.values[a.path]), b.values.index(p.values[b.path])
            if p.feasible and p.objective is not None:
                Z[i, j] = p.objective
        mesh = ax.pcolormesh(b.values, a.values, Z, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label=name)
        for p in result.points:
            marker = "o" if p.feasible else "x"
            bind = p.binding[0] if p.binding else "none"
            ax.scatter(p.values[b.path], p.values[a.path], marker=marker, color=color[bind], s=30,
                       linewidths=0.8)
        for bind in binders:
            ax.scatter([], [], color=color[bind], label=f"binding: {bind}")
        front = [p for p in result.points if p.pareto]  # non-dominated over both swept values and the objective
        if front:
            ax.scatter([p.values[b.path] for p in front], [p.values[a.path] for p in front], facecolors="none",
                       edgecolors="black", s=140, lw=1.5, zorder=3, label=f"Pareto front ({len(front)} points)")
        ax.set_xlabel(b.path)
        ax.set_ylabel(a.path)
    ax.set_title(f"Trade-off: {result.spec}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return save_figure(fig, path)


def write_tradeoff_report(result: TradeoffResult, out_dir: str | Path, command: str = "",
                          force: bool = False) -> TradeoffFiles:
    """Write the trade-off files into ``out_dir`` (never over a file synth did not write).

    The files hold no wall-clock time and floats to 12 significant digits: the same study gives the same bytes.
    """
    out = OutputDir(out_dir, force)
    csv_path = out.claim("tradeoff.csv")
    csv_path.write_text(tradeoff_csv(result), encoding="utf-8")
    json_path = out.claim("tradeoff.json")
    data = reproducible(result.to_dict())
    json_path.write_text(dump_json(data), encoding="utf-8")
    png = tradeoff_figure(result, out.claim("tradeoff.png"))
    feasible = [p for p in result.points if p.feasible]
    html = render(
        "tradeoff.html.j2", r=data, generator=GENERATOR, command=command, feasible=len(feasible), total=len(result.points),
        front=[p for p in data["points"] if p["pareto"]], f=lambda x, d=4: fmt(None if x is None else float(x), d),
    )
    html_path = out.claim("tradeoff.html")
    html_path.write_text(html, encoding="utf-8")
    out.commit()
    return TradeoffFiles(out.path, out.final(csv_path), out.final(json_path), out.final(html_path), out.final(png))
