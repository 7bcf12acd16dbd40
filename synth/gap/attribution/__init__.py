"""Which effect closes the gap, and how far: fits of the candidate effects judged on held-out data.

:mod:`~synth.gap.attribution.refit` (the nominal coefficients re-fitted jointly with an effect, casadi;
golden-section search :mod:`~synth.gap.attribution.golden`), :mod:`~synth.gap.attribution.screen`
(cheap screening with the denominator held), :mod:`~synth.gap.attribution.candidates` (screened, the
best confirmed jointly), :mod:`~synth.gap.attribution.composite` (two effects in series) and
:mod:`~synth.gap.attribution.forward` (forward selection of a second effect);
:mod:`~synth.gap.attribution.calibration` (noise floor, parametric-bootstrap threshold),
:mod:`~synth.gap.attribution.parsimony` (the simplest candidate not beaten significantly),
:mod:`~synth.gap.attribution.verdict` (result types, wording) and
:mod:`~synth.gap.attribution.heldout` (:func:`~synth.gap.attribution.heldout.diagnose_effects`: the
held-out shrinkage, the whole procedure). Several runs: :mod:`~synth.gap.attribution.stitch` (held out
together) and :mod:`~synth.gap.attribution.roundrobin` (each run fitted once, the others held out).
The modules are imported by their full path (this package imports nothing).
"""

__all__: list[str] = []
