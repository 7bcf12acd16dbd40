"""The seed paper's own section of a design report: sizing, the disturbance chain, every unreconciled number.

A spec asks for it with ``analysis: {paper: x4}`` (``docs/spec-format.md``). For the X-4 Flyer paper
(``../shared/seeds/x4_rotor_drive_sysid_and_control.md``) the section holds, all computed by synth:

- **the disturbance chain** (sec. 5, 6A) run on a SYNTHETIC record generated from the paper's stated
  spectrum (:mod:`synth.ident.disturbance_synthetic`): spectrum -> sensitivity level and band -> bandwidth
  floor (:func:`synth.ident.disturbance_requirements.requirements_from_records`), with the paper's numbers
  beside synth's, the ready ``requirements:`` block, the evidence and the figure. The record is made from
  the paper's numbers, so agreement shows that the chain recovers them, not that the paper is right;
- **the rotor and drive sizing** (sec. 3, momentum theory; :func:`synth.sizing.rotor_sizing`) and the
  paper's section 2-3 numbers beside synth's (:func:`synth.sizing.sizing_checks`);
- **one table of every paper number that does not reconcile** (paper value, synth value, what would
  reconcile it; :func:`synth.paper_checks.x4_paper_checks`), eq. 15's slow pole pair included.

:func:`paper_section_data` (into ``result.json``) and :func:`paper_section_figures` are the design report's
hooks; the HTML is ``templates/paper_section.html.j2``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

from synth.disk_cache import cached, enabled
from synth.ident.disturbance_requirements import DisturbanceRequirements, requirements_from_records
from synth.ident.disturbance_requirements_figure import disturbance_requirements_plot
from synth.ident.disturbance_synthetic import X4_SYNTHETIC_SHAPE, synthetic_disturbance_record, synthetic_noise_record
from synth.ident.psd import PsdAnalysis
from synth.outputs import OutputDir, to_jsonable
from synth.paper_checks import PaperTable, x4_paper_checks
from synth.paper_row import PaperRow
from synth.sizing import RHO_SEA_LEVEL, RotorSizing, rotor_sizing, sizing_checks
from synth.spec import Spec

__all__ = ["SIZING_SHOWN", "X4_RESOLUTION", "ChainStep", "PaperSection", "paper_figures", "paper_section_data",
           "paper_section_figures", "x4_paper_section"]

#: the speed sensor's resolution the paper states (sec. 4B) [rad/s]
X4_RESOLUTION = 1.2

#: the sizing numbers the report lists, in order (names of :class:`synth.sizing.RotorSizing` fields)
SIZING_SHOWN = ("thrust", "radius", "rho", "area", "induced_velocity", "induced_power", "speed", "max_torque",
                "current_limit", "torque_constant", "shaft_power", "max_thrust_ideal", "required_figure_of_merit",
                "torque_for_induced_power", "current_for_induced_power", "battery_voltage", "battery_current",
                "electrical_power_at_limit", "shaft_over_electrical")


@dataclass(frozen=True)
class ChainStep:
    """One step of the paper's disturbance chain: what the paper says, what generated the record, what synth read.

    Examples
    --------
    >>> ChainStep("corner", "30", 30.0, 30.2, "rad/s", "end of the plateau").to_dict()["synth"]
    30.2
    """

    quantity: str
    paper: str
    generated: float | None
    synth: float | None
    unit: str
    how: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"quantity": self.quantity, "paper": self.paper, "generated": self.generated, "synth": self.synth,
                "unit": self.unit, "how": self.how}


@dataclass(frozen=True)
class PaperSection:
    """Everything the report's paper section shows (see the module text).

    Attributes
    ----------
    paper : str
        Which paper (``"x4"``).
    record_source : str
        The disturbance record's source; it says SYNTHETIC.
    resolution : float
        Sensor resolution given to the chain [rad/s].
    chain : tuple of ChainStep
        Paper, generating spectrum and synth's reading, step by step.
    disturbance : DisturbanceRequirements
    sizing : RotorSizing
    sizing_rows : tuple of PaperRow
        The paper's section 2-3 numbers beside synth's.
    table : PaperTable
        Every checked paper number; :meth:`disagreements` are those that do not reconcile.
    analysis : PsdAnalysis
        The spectrum the chain read (for the figure; not in :meth:`to_dict`).
    """

    paper: str
    record_source: str
    resolution: float
    chain: tuple[ChainStep, ...]
    disturbance: DisturbanceRequirements
    sizing: RotorSizing
    sizing_rows: tuple[PaperRow, ...]
    table: PaperTable
    analysis: PsdAnalysis = field(repr=False)

    def disagreements(self) -> list[PaperRow]:
        """The paper numbers that do not reconcile (one table in the report)."""
        return self.table.disagreements()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (the report's ``paper_section``)."""
        sizing = self.sizing.to_dict()
        return to_jsonable({
            "paper": self.paper, "record_source": self.record_source, "synthetic": "SYNTHETIC" in self.record_source,
            "resolution": self.resolution, "chain": [s.to_dict() for s in self.chain],
            "disturbance": self.disturbance.to_dict(),
            "sizing": {k: sizing[k] for k in SIZING_SHOWN},
            "sizing_rows": [r.to_dict() for r in self.sizing_rows],
            "disagreements": [r.to_dict() for r in self.disagreements()],
            "checked": len(self.table.rows),
        })


@lru_cache(maxsize=4)
def x4_paper_section(resolution: float = X4_RESOLUTION, rho: float = RHO_SEA_LEVEL, gain: float = 3.0,
                     duration: float = 70.0) -> PaperSection:
    """The X-4 paper's section: disturbance chain on the SYNTHETIC record, sizing, non-reconciliations.

    Parameters
    ----------
    resolution : float
        Speed-sensor resolution [rad/s] (1.2, sec. 4B).
    rho : float
        Air density for the sizing [kg/m^3] (ISA sea level; the paper states none).
    gain : float
        The paper's proportional gain (3).
    duration : float
        Length of the SYNTHETIC disturbance and noise records [s] (70 s at 1 kHz, as the paper's tests).

    Returns
    -------
    PaperSection
        Cached: the same arguments return the same (frozen) section; also kept on disk between runs
        (:mod:`synth.disk_cache`, ``SYNTH_RESULT_CACHE=off`` turns that off).

    Examples
    --------
    >>> s = x4_paper_section()
    >>> round(s.disturbance.max_db), round(s.disturbance.band[1]), round(s.disturbance.min_bandwidth)
    (-15, 30, 65)
    >>> [r.quantity for r in s.disagreements() if r.quantity.startswith("eq. 15 slow")]
    ['eq. 15 slow pole (measured)']
    """
    if enabled():  # it depends on its arguments and the code alone: kept on disk between runs
        return cached("paper_section", ["x4", repr((resolution, rho, gain, duration))],
                      lambda: _x4_section(resolution, rho, gain, duration))
    return _x4_section(resolution, rho, gain, duration)


def _x4_section(resolution: float, rho: float, gain: float, duration: float) -> PaperSection:
    record = synthetic_disturbance_record(duration=duration)
    analysis, req = requirements_from_records([record], [synthetic_noise_record(duration=duration)],
                                              resolution=resolution)
    shape = X4_SYNTHETIC_SHAPE
    spikes = ", ".join(f"{s.w:.0f}" for s in analysis.spikes) or "none"
    chain = (
        ChainStep("disturbance power lies below (plateau corner)", "30", shape.corner, req.band[1], "rad/s",
                  "end of the fitted plateau; sets the band of the sensitivity requirement"),
        ChainStep("sensor noise floor", "-30 (Fig. 5)", shape.floor_db, req.sensor_floor_db, "dB",
                  f"largest of the noise record's floor and the {resolution:g} rad/s quantization floor "
                  f"({req.sensor_floor_source} sets it)"),
        ChainStep("sensitivity level needed", "-15", shape.attenuation_db, req.max_db, "dB",
                  "sensor floor - plateau: attenuating further would push the disturbance below what the sensor "
                  "resolves"),
        ChainStep("bandwidth floor (acceptable)", "60", shape.frequency_above_floor(req.margin_db), req.min_bandwidth,
                  "rad/s", f"the fitted disturbance falls to {req.margin_db:g} dB above the sensor floor"),
        ChainStep("bandwidth (ideal)", "80", shape.meets_floor, req.ideal_bandwidth, "rad/s",
                  "the fitted disturbance meets the sensor floor"),
        ChainStep("supply spikes", "150-300", None, None, "rad/s",
                  f"found at {spikes} rad/s: narrow bands, a notch rather than bandwidth"),
    )
    return PaperSection("x4", record.source, float(resolution), chain, req, rotor_sizing(rho=rho),
                        tuple(sizing_checks(rho)), x4_paper_checks(rho, gain), analysis)


def paper_figures(section: PaperSection, out: OutputDir) -> dict[str, Path]:
    """Draw the section's figure (the disturbance spectrum with the requirements read from it) into ``out``.

    Examples
    --------
    >>> import tempfile
    >>> out = OutputDir(tempfile.mkdtemp())
    >>> figures = paper_figures(x4_paper_section(), out); out.commit()
    >>> [(k, out.final(p).name) for k, p in figures.items()]
    [('paper_disturbance', 'paper_disturbance_requirements.png')]
    """
    path = disturbance_requirements_plot(section.analysis, section.disturbance,
                                         out.claim("paper_disturbance_requirements.png"),
                                         title="SYNTHETIC disturbance record from the X-4 paper's stated spectrum")
    return {"paper_disturbance": path}


def paper_section_data(spec: Spec) -> dict[str, Any]:
    """The design report's data hook: ``{"paper_section": ...}`` when the spec asks (``analysis: {paper: x4}``),
    ``{}`` otherwise (merged into ``result.json``).

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> sorted(paper_section_data(spec)["paper_section"])[:3], len(paper_section_data(spec)["paper_section"]["chain"])
    (['chain', 'checked', 'disagreements'], 6)
    >>> paper_section_data(spec.model_copy(update={"analysis": spec.analysis.model_copy(update={"paper": None})}))
    {}
    """
    if spec.analysis.paper != "x4":
        return {}
    return {"paper_section": x4_paper_section().to_dict()}


def paper_section_figures(spec: Spec, out: OutputDir) -> dict[str, Path]:
    """The design report's figure hook: the section's figures drawn into ``out`` when the spec asks, else ``{}``.

    Examples
    --------
    >>> import tempfile
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> paper_section_figures(spec.model_copy(update={"analysis": spec.analysis.model_copy(update={"paper": None})}),
    ...                       OutputDir(tempfile.mkdtemp()))
    {}
    """
    if spec.analysis.paper != "x4":
        return {}
    return paper_figures(x4_paper_section(), out)
