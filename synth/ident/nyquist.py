"""Poles and zeros of a fitted plant beyond the record's Nyquist frequency, which samples ``dt`` apart cannot
resolve: a fit may still put them there (a fast pair whose product stands in for a gain, a mode aliased from
above), and the result must say so."""

from __future__ import annotations

import numpy as np

from synth.plant import Plant

__all__ = ["beyond_nyquist", "nyquist_note"]


def _outside(plant: Plant, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The poles and the zeros of ``plant`` whose magnitude exceeds ``pi / dt``."""
    limit = np.pi / dt
    poles, zeros = np.asarray(plant.poles()), np.asarray(plant.zeros())
    return poles[np.abs(poles) > limit], zeros[np.abs(zeros) > limit]


def beyond_nyquist(plant: Plant, dt: float) -> bool:
    """Whether ``plant`` has a pole or zero beyond the Nyquist frequency of samples ``dt`` apart, which no such
    record resolves.

    Examples
    --------
    >>> G = Plant.from_string("(s+5e4)/((s+1)*(s+3.7e4))")                     # Nyquist of 5 ms: 628 rad/s
    >>> beyond_nyquist(G, 0.005), beyond_nyquist(Plant.from_string("1/(s+1)"), 0.005)
    (True, False)
    """
    poles, zeros = _outside(plant, dt)
    return bool(poles.size or zeros.size)


def nyquist_note(plant: Plant, dt: float) -> str:
    """One sentence on the poles and zeros of a fitted ``plant`` beyond the Nyquist frequency of samples ``dt``
    apart ('' when there are none): where they are, and what the model is worth there.

    Examples
    --------
    >>> nyquist_note(Plant.from_string("1/(s+1)"), 0.005)
    ''
    >>> note = nyquist_note(Plant.from_string("1e6/(s^2+200*s+1e6)"), 0.005)  # a mode at 1000 rad/s, z = 0.1
    >>> print(note.replace(": ", ":\\n").replace(", so", ",\\nso"))
    the fitted plant has poles at 1000 rad/s (damping 0.1), beyond the record's Nyquist frequency 628.3 rad/s:
    samples 0.005 s apart cannot resolve them,
    so the model says nothing of the plant above 628.3 rad/s (a lag there acts as a small delay, a mode there is aliased)
    """
    poles, zeros = _outside(plant, dt)
    if not poles.size and not zeros.size:
        return ""

    def where(roots: np.ndarray) -> str:
        shown = []
        for r in sorted(roots[roots.imag >= 0], key=abs):
            text = f"{abs(r):.4g} rad/s"
            if abs(r.imag) > 1e-9 * abs(r):
                text += f" (damping {-r.real / abs(r):.2g})"
            shown.append(text)
        return ", ".join(shown)

    parts = [(f"a {kind} at " if roots.size == 1 else f"{kind}s at ") + where(roots)
             for kind, roots in (("pole", poles), ("zero", zeros)) if roots.size]
    limit = np.pi / dt
    them = "it" if poles.size + zeros.size == 1 else "them"
    return (f"the fitted plant has {' and '.join(parts)}, beyond the record's Nyquist frequency {limit:.4g} rad/s: "
            f"samples {dt:.4g} s apart cannot resolve {them}, so the model says nothing of the plant above "
            f"{limit:.4g} rad/s (a lag there acts as a small delay, a mode there is aliased)")
