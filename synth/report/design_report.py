"""The design report: ``result.json``, ``report.html`` and PNG figures in one folder."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.forked import run_beside
from synth.loop import Loop
from synth.outputs import GENERATOR, OutputDir, dump_json, to_jsonable
from synth.reference import compare
from synth.report import feasibility_map, figures
from synth.report.templating import render, reproducible, unit_text
from synth.requirements import SlewRate
from synth.requirements.base import Requirement, fmt, unique_names
from synth.results import DesignResult, reference_controller
from synth.spec import Spec
from synth.synthesis.gainset import SlackBatch
from synth.synthesis.scalar import scalar_family

__all__ = ["ReportFiles", "report_data", "slack_curves", "write_design_report"]


@dataclass
class ReportFiles:
    """Paths written by :func:`write_design_report`."""

    folder: Path
    result_json: Path
    html: Path
    figures: dict[str, Path]


def report_data(spec: Spec, result: DesignResult, keep: dict[str, Any] | None = None,
                studies: dict[str, Any] | None = None) -> dict[str, Any]:
    """Everything ``result.json`` holds: the design result, the reference controller's check and
    the comparisons with published numbers; floats to 12 significant digits, no wall-clock times (the same
    inputs give the same bytes). ``studies`` holds results of :func:`spec_studies`' jobs computed already.

    Examples
    --------
    >>> from synth.spec import parse_spec; from synth.design import design
    >>> spec = parse_spec({"name": "p", "plant": {"tf": "4/((s+1)*(s+3))", "delay": 0.05},
    ...     "controller": {"type": "P", "bounds": {"kp": [0, 10]}}, "reference": {"controller": "P(1)"},
    ...     "requirements": [{"type": "peak_sensitivity", "max_db": 6}], "objective": {"maximize": "crossover"}})
    >>> data = report_data(spec, design(spec))
    >>> data["feasible"], data["reference_check"]["feasible"]
    (True, True)
    """
    shown = result.controller or (result.compromise.controller if result.compromise else None)
    data = result.to_dict()
    data["analysis"] = compare(spec, shown)
    data["description"] = spec.description
    ident = spec.plant.identification()
    if ident is not None:  # plant identified from a record (issue 4): parameters, uncertainty, fit
        fit = ident.to_dict()
        data["identification"] = {
            key: fit[key] for key in ("structure", "parameters", "std", "ci95", "fit_percent", "tf", "delay",
                                      "delay_fitted", "offset", "residual_std", "samples", "record", "averaging",
                                      "whole_record")
        } | {"in_loop_delay": spec.plant.identify.in_loop_delay, "confidence": spec.plant.identify.confidence,
             "uncertainty_plants": [p.label for p in spec.plants()[1:] if p.label.startswith("identified")],
             "sensor": spec.plant.identify.sensor}
    if spec.simulation is not None:  # nonlinear step check (issue 5): logic in synth.report.simulation_report
        from synth.report.simulation_report import simulation_report

        studies = studies or {}
        data["simulation"] = simulation_report(spec, shown, reference_controller(spec),
                                               studies=studies.get("simulation")).data
        from synth.gap.x4_case import gap_case_applies, x4_gap_case

        if "gap_case" in studies:
            case, objects = studies["gap_case"]
            data["sim_to_real_gap"] = case
            if keep is not None:
                keep.update(objects)
        elif gap_case_applies(spec):  # seed 1's gap diagnosed on the simulated rig (issue 6): synth.gap.x4_case
            data["sim_to_real_gap"] = x4_gap_case(spec, objects=keep)
    if spec.analysis.paper is not None:  # the seed paper's own section (issue 19): synth.report.paper_section
        from synth.report.paper_section import paper_section_data

        data |= paper_section_data(spec)
    return reproducible(to_jsonable(data))


_FIGURE_ORDER = ("bode", "sensitivity", "step", "gain_set", "region", "delay")

_JOB_WEIGHT = {"region": 3, "region-columns": 3, "gap_case": 2}
"""Rough cost of the report's figure jobs (others 1): a feasibility grid's part 0.3-2 s, seed 1's gap figures
0.4 s, a single figure 0.1-0.2 s."""


def _design_figure_jobs(spec: Spec, result: DesignResult, loops: list[tuple[str, Loop]], marks: dict[str, float],
                        ref: Controller | None, result_data: dict[str, Any], out: OutputDir,
                        curves: dict[str, tuple[np.ndarray, np.ndarray]] | None = None) -> list[tuple[str, Any]]:
    """``(figure key, job)`` for the figures that need only the design; each job returns ``(path or None,
    the requirement bounds it drew or None, the file names it claimed)``."""

    def job(draw: Any, with_bounds: bool = False) -> Any:
        def run() -> tuple[Path | None, list[dict[str, Any]] | None, list[str]]:
            before = len(out.written)
            drawn: list[dict[str, Any]] = []
            path = draw(drawn) if with_bounds else draw()
            return path, drawn if with_bounds else None, list(out.written[before:])
        return run

    jobs: list[tuple[str, Any]] = []
    if result.gain_set is None and result.controller is not None \
            and len(spec.controller.free_parameters()) == 2:
        size = feasibility_map.map_grid_size(spec)
        if len(spec.plants()) == 1 and size == feasibility_map.MAP_GRID and not any(r.costly for r in spec.requirements):
            jobs.append(("region", job(lambda: feasibility_map.feasibility_map(
                spec, result.controller, out.claim("feasible_region.png"), reference=ref))))
        elif len(spec.plants()) == 1:  # a requirement that simulates (vectorized or point by point): every other
            # column per job
            for k in range(2):
                jobs.append((f"region-columns:{k}", lambda k=k: (
                    feasibility_map.feasibility_grid(spec, result.controller, columns=slice(k, None, 2)), None, [])))
        else:  # the plane's grid one plant per job (both cores share them), drawn when all are in
            for k in range(len(spec.plants())):
                jobs.append((f"region:{k}", lambda k=k: (
                    feasibility_map.feasibility_grid(spec, result.controller, plants=[k]), None, [])))
    gain = result_data.get("gain_set_detail")
    if gain is not None:  # the heavier jobs first: the worker starts on them
        jobs.append(("gain_set", job(lambda: figures.gain_set_plot(
            gain["parameter"], tuple(gain["bounds"]),
            curves if curves is not None else slack_curves(_gain_set_spec(spec)),
            result_data["gain_set"], marks, out.claim("gain_set.png")))))
    slew = [r for r in spec.requirements if isinstance(r, SlewRate)]
    if slew and loops:
        jobs.append(("bode", job(lambda drawn: figures.bode_with_slew_bound(
            loops, slew, out.claim("bode_slew_bound.png"), drawn=drawn), True)))
    if loops:
        jobs.append(("sensitivity", job(lambda drawn: figures.sensitivity_plot(
            loops, list(spec.requirements), out.claim("sensitivity.png"), drawn=drawn), True)))
    if loops:
        jobs.append(("step", job(lambda drawn: figures.step_plot(
            loops, out.claim("step_response.png"), requirements=list(spec.requirements), drawn=drawn), True)))
    return jobs


def _study_figure_jobs(spec: Spec, studies: dict[str, Any] | None, out: OutputDir) -> list[tuple[str, Any]]:
    """``(key, job)`` for the figures of what is known before the report's own work: seed 1's gap case when the
    command computed it beside the design, and the seed paper's section (the spec alone); each job returns
    ``({figure key: path}, None, the file names it claimed)`` like :func:`_design_figure_jobs`' jobs."""

    def job(draw: Any) -> Any:
        def run() -> tuple[dict[str, Path], None, list[str]]:
            before = len(out.written)
            figs = draw()
            return figs, None, list(out.written[before:])
        return run

    jobs: list[tuple[str, Any]] = []
    objects = (studies or {}).get("gap_case", (None, {}))[1]
    if "diagnosis" in objects:
        jobs.append(("gap_case", job(lambda: _gap_figures(objects["diagnosis"], out))))
    if spec.analysis.paper is not None:
        from synth.report.paper_section import paper_section_figures

        jobs.append(("paper", job(lambda: paper_section_figures(spec, out))))
    return jobs


def _gap_figures(diag: Any, out: OutputDir) -> dict[str, Path]:
    """Seed 1's gap case: the gap map and the before/after overlay of the simulated rig."""
    from synth.figure_files import save_figure
    from synth.gap.overlay import overlay_figure
    from synth.gap.where.gapmap import write_gap_map

    return {"gap_map": write_gap_map(diag.localization, out.claim("gap_map.png"), diag.plant),
            "gap_overlay": save_figure(overlay_figure(diag.attribution), out.claim("gap_overlay.png"))}


def _analysis_figures(spec: Spec, data: dict[str, Any], objects: dict[str, Any], shown: Controller | None,
                      ref: Controller | None, marks: dict[str, float], out: OutputDir,
                      elsewhere: frozenset[str] = frozenset()) -> dict[str, Path]:
    """The figures drawn from ``report_data``'s results (delay table, simulations, gap case, paper section),
    except the groups (``"gap_case"``, ``"paper"``) the worker draws (:func:`_study_figure_jobs`)."""
    figs: dict[str, Path] = {}
    delay_table = data["analysis"].get("delay_table")
    if delay_table:
        rows = [{**r, "critical_gain": float(r["critical_gain"])} for r in delay_table]
        figs["delay"] = figures.delay_chart(rows, marks, out.claim("critical_gain_vs_delay.png"))
    if spec.simulation is not None:
        from synth.report.simulation_report import simulation_figures

        figs.update(simulation_figures(spec, shown, ref, out, marks))
    if "diagnosis" in objects and "gap_case" not in elsewhere:  # the seed-1 gap case (simulated rig)
        figs.update(_gap_figures(objects["diagnosis"], out))
    if spec.analysis.paper is not None and "paper" not in elsewhere:  # the seed paper's own section (issue 19)
        from synth.report.paper_section import paper_section_figures

        figs.update(paper_section_figures(spec, out))
    return figs


def _gain_set_spec(spec: Spec) -> Spec:
    """The spec a design's gain set is over: the spec itself with one free parameter; a PI or PID whose design
    without integral action won (its gain set is over the proportional gain) with ``ki`` fixed at 0."""
    if len(spec.controller.free_parameters()) == 1:
        return spec
    from synth.synthesis.integral_action import without_integral_action

    return without_integral_action(spec) or spec


def slack_curves(spec: Spec) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each requirement's worst slack over the plants against the spec's one free parameter (vectorized,
    121 values over its bounds): the curves of the report's gain-set figure.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> curves = slack_curves(load_spec("specs/x4_rotor.yaml"))
    >>> sorted(curves)[0], curves["bandwidth"][0].size
    ('bandwidth', 121)
    """
    family, (lo, hi) = scalar_family(spec)
    xs = np.linspace(lo, hi, 121)
    fast = SlackBatch(family, spec.plants(), per_decade=40)
    return {req.name(): (xs, fast.slack(req, xs)) for req in spec.requirements}


def _columns(data: dict[str, Any], requirements: list[Requirement]) -> tuple[list[dict], list[dict]]:
    """Table columns (design, compromise, reference) and rows: stability, then the spec's requirements in
    order, each row's relation to its bound from the requirement's own class. Each cell keeps the JSON
    pointer of its entry in ``result.json`` and the plant its value is on."""
    cols = []
    if data.get("controller"):
        cols.append(("design " + data["controller"]["text"], "/requirements", data["requirements"]))
    elif data.get("compromise"):
        cols.append(("best compromise " + data["compromise"]["controller"]["text"] + " (not a solution)",
                     "/compromise/requirements", data["compromise"]["requirements"]))
    if data.get("reference_check"):
        cols.append(("reference " + data["reference_check"]["controller"]["text"], "/reference_check/requirements",
                     data["reference_check"]["requirements"]))
    columns = [{"title": t, "messages": [(f"{ptr}/{i}/message", r["message"]) for i, r in enumerate(reqs)]}
               for t, ptr, reqs in cols]
    rows = []
    for i, r0 in enumerate(cols[0][2] if cols else []):
        cells = []
        for _, ptr, reqs in cols:
            r = reqs[i]
            word = None if r["type"] != "stability" else ("stable" if r["met"] else "UNSTABLE")
            cells.append({"ptr": f"{ptr}/{i}", "word": word, "value": r["value"], "unit": unit_text(r["unit"]),
                          "slack": r["slack"], "met": r["met"], "plant": r.get("plant", "nominal")})
        if r0["type"] == "stability":  # the check's own first row, not a spec requirement
            bound = None
        else:
            bound = {"relation": requirements[i - 1].bound_of(_num(r0["bound"])).relation, "value": r0["bound"],
                     "unit": unit_text(r0["unit"]), "ptr": f"{cols[0][1]}/{i}/bound"}
        rows.append({"label": r0["label"], "cells": cells, "bound": bound})
    return columns, rows


def _num(x: Any) -> float | None:
    if x is None:
        return None
    if isinstance(x, str):
        return float(x)
    return float(x)


def write_design_report(spec: Spec, result: DesignResult, out_dir: str | Path, *, command: str = "",
                        force: bool = False,
                        curves: dict[str, tuple[np.ndarray, np.ndarray]] | None = None,
                        studies: dict[str, Any] | None = None) -> ReportFiles:
    """Write ``result.json``, ``report.html`` and figures for a design into ``out_dir``.

    Files synth wrote earlier are replaced; any other existing file of the
    same name is left alone (:class:`~synth.errors.OutputExistsError`) unless
    ``force`` is given. ``curves`` are the gain-set figure's :func:`slack_curves` when the caller has them
    already (the design command computes them beside the design), ``studies`` the results of
    :func:`synth.report.studies.spec_studies`' jobs.

    Examples
    --------
    A P loop behind 50 ms with a peak-sensitivity bound (``specs/x4_rotor.yaml`` adds the Bode, gap and
    simulation figures its requirements and reference call for):

    >>> import tempfile
    >>> from synth.spec import parse_spec; from synth.design import design
    >>> spec = parse_spec({"name": "p", "plant": {"tf": "4/((s+1)*(s+3))", "delay": 0.05},
    ...     "controller": {"type": "P", "bounds": {"kp": [0, 10]}},
    ...     "requirements": [{"type": "peak_sensitivity", "max_db": 6}], "objective": {"maximize": "crossover"}})
    >>> files = write_design_report(spec, design(spec), tempfile.mkdtemp())
    >>> sorted(files.figures)
    ['delay', 'gain_set', 'sensitivity', 'step']
    """
    out = OutputDir(out_dir, force)
    _ = out.staging  # made before the figure worker forks: both processes write into this one folder
    plant = spec.nominal_plant()
    loops: list[tuple[str, Loop]] = []
    shown = result.controller or (result.compromise.controller if result.compromise else None)
    if shown is not None:
        loops.append(("design " + str(shown) if result.controller else "compromise " + str(shown),
                      Loop(plant, shown)))
    ref = reference_controller(spec)
    if ref is not None:
        loops.append(("reference " + str(ref), Loop(plant, ref)))
    marks: dict[str, float] = {}
    for name, loop in loops:
        if isinstance(loop.controller, Controller) and loop.controller.type == "P":
            marks[name] = loop.controller.parameters["kp"]
    result_data = reproducible(to_jsonable(result.to_dict()))
    # figures that need only the design: drawn by a forked worker while this process computes report_data
    jobs = _design_figure_jobs(spec, result, loops, marks, ref, result_data, out, curves)
    study_jobs = _study_figure_jobs(spec, studies, out)  # the worker also draws what needs no report data
    # the longest first (the worker takes them in order, this process what is left once its own work is done)
    jobs = sorted(jobs + study_jobs, key=lambda job: -_JOB_WEIGHT.get(job[0].split(":")[0], 1))
    objects: dict[str, Any] = {}

    def own_work() -> tuple[dict[str, Any], dict[str, Path]]:
        data = report_data(spec, result, keep=objects, studies=studies)
        return data, _analysis_figures(spec, data, objects, shown, ref, marks, out,
                                       frozenset(key for key, _ in study_jobs))

    drawn_by_worker, (data, figs) = run_beside([job for _, job in jobs], own_work)
    bounds: dict[str, list[dict[str, Any]]] = {}  # figure -> the requirement bounds it draws
    plane, halves = [], []
    for (key, _), (path, drawn, claimed) in zip(jobs, drawn_by_worker):
        for name in claimed:  # names the worker claimed in its copy of ``out``
            out.claim(name)
        if key.startswith("region:"):
            plane.append(path)
        elif key.startswith("region-columns:"):
            halves.append(path)
        elif isinstance(path, dict):  # a study's group of figures
            figs.update(path)
        elif path is not None:
            figs[key] = path
        if drawn is not None:
            bounds[key] = drawn
    if plane or halves:
        grid = feasibility_map.combine_grids(plane) if plane else feasibility_map.join_columns(halves)
        figs["region"] = feasibility_map.feasibility_map(spec, result.controller, out.claim("feasible_region.png"),
                                                 reference=ref, grid=grid)
    figs = {key: figs[key] for key in _FIGURE_ORDER if key in figs} | figs
    gain = data.get("gain_set_detail")

    columns, rows = _columns(data, list(spec.requirements))
    ref_line = ""
    html = render(
        "design.html.j2",
        r=data | {"generator": GENERATOR},
        description=spec.description,
        command=command or f"synth design SPEC --out {out.path}",
        plant=data["analysis"]["plant"],
        structure=spec.controller.kind().formula + "; bounds "
        + ", ".join(f"{k} in [{fmt(a)}, {fmt(b)}]" for k, (a, b) in spec.controller.all_bounds().items()),
        columns=columns, rows=rows, gain=gain, unevaluated=[] if rows else unique_names(list(spec.requirements)),
        figures={k: v.name for k, v in figs.items()},
        loops=data["analysis"]["loops"],
        published=(data["analysis"].get("reference") or {}).get("published_closed_loops", []),
        reference=data["analysis"].get("reference"),
        slew=data["analysis"].get("slew_rate", []),
        delay_table=[{**r, "critical_gain": float(r["critical_gain"])}
                     for r in data["analysis"].get("delay_table") or []],
        marks=marks, certificate=data.get("certificate"), ref_line=ref_line, sim=data.get("simulation"),
        synthesis=data.get("synthesis"), diagnosis=data.get("diagnosis"), ident=data.get("identification"),
        f=lambda x, d=4: fmt(None if x is None else float(x), d), gap=data.get("sim_to_real_gap"),
        bounds=bounds, plants=[p.label for p in spec.plants()], unit=unit_text,
    )
    html_path = out.claim("report.html")
    html_path.write_text(html, encoding="utf-8")
    json_path = out.claim("result.json")
    json_path.write_text(dump_json(data), encoding="utf-8")
    out.commit()
    return ReportFiles(out.path, out.final(json_path), out.final(html_path), {k: out.final(p) for k, p in figs.items()})
