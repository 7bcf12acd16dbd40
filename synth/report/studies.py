"""The design report's studies that depend on the spec alone (not on the design), as independent jobs.

The command line runs them on two cores beside the design (:func:`synth.forked.run_beside`) and hands their
results to :func:`synth.report.design_report.write_design_report`; without them the report computes them
itself. Their results are kept on disk (:mod:`synth.disk_cache`, keyed by the parts of the spec they read and
the code), so that the usual loop, a requirement edited and the design run again, does not redo them
(``SYNTH_RESULT_CACHE=off`` turns that off). This module imports nothing heavy: the jobs import what they
need when they run.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from synth.disk_cache import cached, enabled
from synth.results import reference_controller
from synth.spec import Spec

__all__ = ["spec_studies"]


def spec_studies(spec: Spec) -> list[tuple[str, Callable[[], Any]]]:
    """The report's studies that depend on the spec alone, as ``(name, job)``: the reference controller's
    nonlinear runs, onset study and published statements (``"simulation"``), and seed 1's gap case
    (``"gap_case"``: the case and the objects its figures need). The command line runs them on two cores
    beside the design and hands the results to :func:`write_design_report` as ``studies``.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> [name for name, _ in spec_studies(load_spec("specs/x4_rotor.yaml"))]
    ['simulation', 'gap_case']
    """
    jobs: list[tuple[str, Callable[[], Any]]] = []
    ref = reference_controller(spec)
    if spec.simulation is None:
        return jobs
    from synth.gap.x4_case import gap_case_applies

    if ref is not None:  # the heavier first (the onset study): the other core starts on it
        def simulation() -> Any:
            from synth.report.simulation_report import simulation_report

            return simulation_report(spec, None, ref)

        jobs.append(("simulation", simulation))
    if gap_case_applies(spec):
        def gap_case() -> tuple[dict[str, Any], dict[str, Any]]:
            from synth.gap.x4_case import x4_gap_case

            objects: dict[str, Any] = {}
            return x4_gap_case(spec, objects=objects), objects

        jobs.append(("gap_case", gap_case))
    if not enabled():
        return jobs
    key = _inputs(spec)
    return [(name, lambda name=name, job=job: cached("studies", [name, *key], job)) for name, job in jobs]


def _inputs(spec: Spec) -> list[bytes | str]:
    """What the studies read of ``spec``: the nominal plant (coefficients, delay, signals), the ``simulation:``
    block and the ``reference:`` block (the key of their results on disk, :mod:`synth.disk_cache`)."""
    plant = spec.nominal_plant()
    return [plant.num.astype(float).tobytes(), plant.den.astype(float).tobytes(), repr(float(plant.delay)),
            repr((plant.input, plant.output)), spec.simulation.model_dump_json() if spec.simulation else "",
            spec.reference.model_dump_json() if spec.reference else ""]
