"""The round-robin report: ``result.json``, ``report.html`` and each fold's overlay in one folder."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from synth.gap.attribution.roundrobin import RunsDiagnosis
from synth.outputs import GENERATOR, OutputDir, dump_json
from synth.report.templating import render
from synth.requirements.base import fmt

__all__ = ["RunsFiles", "write_runs_report"]


@dataclass(frozen=True)
class RunsFiles:
    """Paths written by :func:`write_runs_report`."""

    folder: Path
    result_json: Path
    html: Path
    figures: dict[str, Path]


def write_runs_report(rr: RunsDiagnosis, out_dir: str | Path, *, units: dict[str, str] | None = None,
                      command: str = "", force: bool = False, figures: bool = True, title: str = "",
                      extra: dict[str, Any] | None = None) -> RunsFiles:
    """Write ``result.json``, ``report.html`` and ``fold_<k>.png`` (each fold's overlay) into ``out_dir``.

    Files synth wrote there before are replaced; any other file of the same name is left alone
    (:class:`~synth.errors.OutputExistsError`) unless ``force`` is given.

    Examples
    --------
    >>> import numpy as np, tempfile
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.attribution.roundrobin import diagnose_runs
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> t = np.arange(0, 4, 0.01)
    >>> runs = [record_from_arrays(t, u, simulate_plant(G, t, u) + 0.01 * np.sin(7 * t))
    ...         for u in (np.where(t >= 1, 1.0, 0.0), np.where(t >= 1, 2.0, 1.0))]
    >>> files = write_runs_report(diagnose_runs(G, runs, ["delay"], n_null=2), tempfile.mkdtemp(), figures=False)
    >>> files.html.name, "Each fold" in files.html.read_text()
    ('report.html', True)
    """
    out = OutputDir(out_dir, force)
    json_path = out.claim("result.json")
    html_path = out.claim("report.html")
    figs: dict[str, Path] = {}
    if figures:
        from synth.figure_files import save_figure
        from synth.gap.overlay import overlay_figure

        for k, fold in enumerate(rr.folds, start=1):
            figs[f"fold_{k}"] = save_figure(overlay_figure(fold), out.claim(f"fold_{k}.png"))
    data = {**rr.to_dict(), **(extra or {})}
    html = render("roundrobin.html.j2",
        d=data, units=units or {}, figures={k: p.name for k, p in figs.items()}, title=title or ", ".join(rr.runs),
        command=command, generator=GENERATOR, f=lambda x, digits=4: fmt(None if x is None else float(x), digits))
    json_path.write_text(dump_json(data), encoding="utf-8")
    html_path.write_text(html, encoding="utf-8")
    out.commit()
    return RunsFiles(out.path, out.final(json_path), out.final(html_path), {k: out.final(p) for k, p in figs.items()})
