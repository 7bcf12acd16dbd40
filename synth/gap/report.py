"""The diagnosis report: ``result.json``, ``report.html``, ``gap_map.png`` and ``overlay.png`` in one folder."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from synth.gap.diagnose import Diagnosis
from synth.outputs import GENERATOR, OutputDir, dump_json
from synth.report.templating import render
from synth.requirements.base import fmt

__all__ = ["DiagnosisFiles", "render_diagnosis_html", "write_diagnosis_report"]


@dataclass(frozen=True)
class DiagnosisFiles:
    """Paths written by :func:`write_diagnosis_report`."""

    folder: Path
    result_json: Path
    html: Path
    figures: dict[str, Path]


def render_diagnosis_html(data: dict[str, Any], figures: dict[str, str] | None = None, *, title: str = "",
                          command: str = "", notes: list[str] | None = None) -> str:
    """The HTML page of a diagnosis from its JSON (``Diagnosis.to_dict()``).

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.diagnose import diagnose
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 8, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> y = simulate_plant(G, t, u) + 0.01 * np.random.default_rng(1).normal(size=t.size)
    >>> html = render_diagnosis_html(diagnose(G, record_from_arrays(t, u, y),
    ...                                       candidates=["delay"], n_null=2).to_dict(), title="demo")
    >>> "No gap beyond the measurement noise" in html
    True
    """
    return render("diagnose.html.j2",
        d=data, figures=figures or {}, title=title or data.get("record", {}).get("source", ""), command=command,
        notes=notes or [], generator=GENERATOR, f=lambda x, digits=4: fmt(None if x is None else float(x), digits))


def write_diagnosis_report(diag: Diagnosis, out_dir: str | Path, *, command: str = "", force: bool = False,
                           figures: bool = True, title: str = "", notes: list[str] | None = None,
                           extra: dict[str, Any] | None = None) -> DiagnosisFiles:
    """Write ``result.json``, ``report.html``, ``gap_map.png`` and ``overlay.png`` into ``out_dir``.

    Files synth wrote there before are replaced; any other file of the same name is
    left alone (:class:`~synth.errors.OutputExistsError`) unless ``force`` is given.

    Parameters
    ----------
    diag : Diagnosis
    out_dir : str or Path
    command : str
        Command line that reproduces the report (shown on the page).
    force : bool
        Overwrite files synth did not write.
    figures : bool
        Draw the gap map and the overlay.
    title : str
        Page title (default: the record's source).
    notes : list of str
        Extra notes for the page.
    extra : dict
        Extra keys merged into ``result.json`` (e.g. the data file names).

    Examples
    --------
    >>> import numpy as np, tempfile
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.diagnose import diagnose
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 8, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> y = simulate_plant(G, t, u) + 0.01 * np.random.default_rng(1).normal(size=t.size)
    >>> dg = diagnose(G, record_from_arrays(t, u, y), candidates=["delay"], n_null=2)
    >>> files = write_diagnosis_report(dg, tempfile.mkdtemp(), figures=False)
    >>> files.html.name, sorted(files.figures)
    ('report.html', [])
    """
    out = OutputDir(out_dir, force)
    json_path = out.claim("result.json")
    html_path = out.claim("report.html")
    figs: dict[str, Path] = {}
    if figures:
        from synth.figure_files import save_figure
        from synth.gap.overlay import overlay_figure
        from synth.gap.where.gapmap import write_gap_map

        figs["gap_map"] = write_gap_map(diag.localization, out.claim("gap_map.png"), diag.plant)
        figs["overlay"] = save_figure(overlay_figure(diag.attribution), out.claim("overlay.png"))
    data = {**diag.to_dict(), **(extra or {})}
    html = render_diagnosis_html(data, {k: p.name for k, p in figs.items()}, title=title, command=command,
                                 notes=notes)
    json_path.write_text(dump_json(data), encoding="utf-8")
    html_path.write_text(html, encoding="utf-8")
    out.commit()
    return DiagnosisFiles(out.path, out.final(json_path), out.final(html_path), {k: out.final(p) for k, p in figs.items()})
