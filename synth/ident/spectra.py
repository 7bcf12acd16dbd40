"""Frequency response from sweep records: the composite multi-window estimate and its coherent band.

What is computed, exactly: the segments, spectra, log grid, averages and the composite of several
window lengths in :mod:`synth.ident.spectral_windows`; the coherence, its random error and the
coherent band in :mod:`synth.ident.coherence`. Here ``H = Gxy / Gxx`` and ``gamma^2`` come from the
combined spectra.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from synth.data import Record
from synth.errors import DataError
from synth.ident.coherence import COHERENCE_THRESHOLD, CoherentBand, coherence_from_spectra, coherent_band, random_error
from synth.ident.excitation_edge import excitation_level, run_input_level, trim_to_excitation
from synth.ident.model_phase import anchored_phase
from synth.ident.output_alignment import alignment_samples, band_after_alignment, shifted_runs
from synth.ident.spectral_windows import (
    as_runs,
    check_length,
    combine_windows,
    default_windows,
    log_grid,
    lowest_frequency,
    required_window,
    window_spectra,
)
from synth.ident.sweep_quality import UNDER_EXCITED_DB, excitation_deficit

__all__ = ["DEFAULT_TOP", "LOOK_AHEAD_CAP", "LOOK_AHEAD_MIN_DECADES", "FrequencyResponse", "correct_response",
           "frequency_response", "rate_to_attitude"]

#: default upper end of the estimate, as a fraction of the Nyquist frequency
DEFAULT_TOP = 0.2
#: how far above the default top the estimate looks for coherent, excited data (fraction of Nyquist)
LOOK_AHEAD_CAP = 0.8
#: the coherent band must go on at least this far above the default top [decades] for a note
LOOK_AHEAD_MIN_DECADES = 0.05


@dataclass(frozen=True)
class FrequencyResponse:
    """An identified frequency response on a log grid.

    Attributes
    ----------
    w : numpy.ndarray
        Frequencies [rad/s].
    H : numpy.ndarray
        Complex response ``Gxy / Gxx``.
    coherence : numpy.ndarray
        ``gamma^2``.
    random_error : numpy.ndarray
        Normalized random error of ``|H|`` (also the phase error in rad).
    n_averages : numpy.ndarray
        Equivalent independent averages ``n_d``.
    gxx, gyy : numpy.ndarray
        Input and output auto-spectra [unit^2/(rad/s)].
    gxy : numpy.ndarray
        Cross-spectrum.
    band : CoherentBand
    windows : tuple of float
        Window lengths used [s].
    kind : str
        ``"measured"`` or ``"integrated (1/s)"`` after :func:`rate_to_attitude`.
    input, output : str
        Signal labels.
    sources : tuple of str
        The runs.
    corrections : tuple of str
        Corrections applied (:func:`correct_response`), in words.
    notes : tuple of str
        What the user should know about the range, in words (e.g. data beyond the default top).
    above_default_top : dict or None
        With the default upper end, when the coherent band reaches it and the data support more:
        ``default_top``, ``coherent_to``, ``excited_to`` [rad/s], and ``peak_w`` [rad/s] /
        ``peak_db`` [dB over ``|H|`` at the default top] when ``|H|`` rises above it by 3 dB or more
        (else ``None``).

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 60, 0.01); u = np.sin(0.5 * t * (1 + t / 10))
    >>> r = frequency_response(record_from_arrays(t, u, 2 * u), w_min=1.0, w_max=10.0)
    >>> bool(np.allclose(r.magnitude_db, 20 * np.log10(2)))
    True
    """

    w: np.ndarray
    H: np.ndarray
    coherence: np.ndarray
    random_error: np.ndarray
    n_averages: np.ndarray
    gxx: np.ndarray
    gyy: np.ndarray
    gxy: np.ndarray
    band: CoherentBand
    windows: tuple[float, ...]
    kind: str = "measured"
    input: str = "u"
    output: str = "y"
    sources: tuple[str, ...] = ()
    corrections: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    above_default_top: dict[str, float | None] | None = None

    @property
    def magnitude_db(self) -> np.ndarray:
        """``20 log10 |H|`` [dB]."""
        return 20.0 * np.log10(np.abs(self.H))

    @property
    def phase_deg(self) -> np.ndarray:
        """Phase [deg], unwrapped along ``w`` and shifted by a multiple of 360 deg so that it lies in (-270, 90] deg
        at the coherent band's lowest frequency (the first point without a band), as ``synth hq`` takes it: the
        points below the band are noise, and anchoring there put an integrator's phase at +250 deg."""
        at = int(np.searchsorted(self.w, self.band.w_min)) if self.band.found else 0
        return anchored_phase(self.H, min(at, self.H.size - 1))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the grid ``w``, ``magnitude_db``, ``phase_deg``, ``coherence``, ``random_error``, band.

        Examples
        --------
        >>> from synth.ident.coherence import coherent_band
        >>> w = np.array([1.0, 2.0]); b = coherent_band(w, np.ones(2) * 0.9)
        >>> r = FrequencyResponse(w, np.array([1j, 1.0]), np.ones(2) * .9, np.ones(2) * .1, np.ones(2),
        ...                       np.ones(2), np.ones(2), np.ones(2, complex), b, (10.0,))
        >>> r.to_dict()["phase_deg"].tolist()
        [90.0, 0.0]
        """
        return {"w": self.w, "magnitude_db": self.magnitude_db, "phase_deg": self.phase_deg,
                "coherence": self.coherence, "random_error": self.random_error, "n_averages": self.n_averages,
                "coherent_band": self.band.to_dict(), "windows_s": list(self.windows), "kind": self.kind,
                "input": self.input, "output": self.output, "sources": list(self.sources),
                "corrections": list(self.corrections), "notes": list(self.notes),
                "above_default_top": self.above_default_top,
                "units": {"w": "rad/s", "magnitude_db": "dB", "phase_deg": "deg"}}


def frequency_response(
    records: Record | Sequence[Record],
    w_min: float | None = None,
    w_max: float | None = None,
    windows: Sequence[float] | None = None,
    overlap: float = 0.5,
    points_per_decade: int = 40,
    coherence_threshold: float = COHERENCE_THRESHOLD,
    detrend: str = "linear",
    align: bool = True,
) -> FrequencyResponse:
    """Composite multi-window frequency response of one or several sweep runs.

    Parameters
    ----------
    records : Record or sequence of Record
        The runs (same sample rate); their segments are averaged together.
    w_min, w_max : float, optional
        Frequency range [rad/s]; defaults: the lowest frequency the runs support
        (:func:`lowest_frequency`) and a fifth of the Nyquist frequency (:data:`DEFAULT_TOP`).
        With the default top, the data above it are looked at up to :data:`LOOK_AHEAD_CAP` of
        Nyquist: when the coherent band reaches the default top and continues above it, the
        result's ``notes`` say how far (and where ``|H|`` peaks there), so that a resonance just
        above a fifth of Nyquist is not missed silently; ``above_default_top`` holds the numbers.
    windows : sequence of float, optional
        Window lengths [s]; default :func:`default_windows`: 5 lengths from the
        longest that fits :data:`MIN_SEGMENTS` times into the runs (at least
        ``2 * 2 pi / w_min``) down to a tenth of ``2 * 2 pi / w_min``. One length
        gives a single-window estimate.
    overlap : float
        Segment overlap fraction (0 <= overlap < 1).
    points_per_decade : int
        Density of the output grid.
    coherence_threshold : float
        For the coherent band (the seed: 0.8).
    detrend : {"linear", "constant", "none"}
        Per-segment detrending.
    align : bool
        Move the output back by the response's delay before windowing where that delay is a material share of
        the shortest window, and put it back in the phase (:mod:`synth.ident.output_alignment`); past the unaligned
        estimate's band, the band is kept only where the input excites as strongly
        (:func:`~synth.ident.output_alignment.band_after_alignment`). False: the windows on the runs as they are.

    Returns
    -------
    FrequencyResponse

    Raises
    ------
    DataError
        Runs too short for ``w_min`` (:func:`check_length`), different sample
        rates, a bad range or window.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> from synth.ident.sweep_design import design_sweep
    >>> G = Plant.from_string("5/(s+2)", delay=0.05)
    >>> t, u = design_sweep(0.4, 10).signal(sample_rate=50)
    >>> r = frequency_response(record_from_arrays(t, u, simulate_plant(G, t, u, "zero")), 0.4, 10)
    >>> k = np.argmin(abs(r.w - 2)); round(float(abs(r.H[k])), 2), round(float(abs(G.freqresp(r.w[k]))), 2)
    (1.77, 1.77)
    """
    runs = as_runs(records)
    first = _composite(runs, w_min, w_max, windows, overlap, points_per_decade, coherence_threshold, detrend)
    k = alignment_samples(first.w, first.H, first.band, runs[0].fs, min(first.windows), min(r.n for r in runs)) \
        if align else 0
    if not k:
        return first
    try:
        aligned = _composite(runs, w_min, w_max, windows, overlap, points_per_decade, coherence_threshold, detrend, k)
    except DataError:  # a window no longer fits the runs shortened by the delay: the estimate as it was
        return first
    note = (f"the output was moved {k / runs[0].fs:.4g} s earlier before windowing (the lower quartile of the "
            "response's group delay over the upper half of the band), and that delay put back in the phase: the "
            "windows then see the output's answer to what their input holds (synth.ident.output_alignment)")
    band = band_after_alignment(first.band, aligned.band, aligned.w, run_input_level(runs, aligned.w))
    if first.band.found and band.found and (band.w_min, band.w_max) != (aligned.band.w_min, aligned.band.w_max):
        note += (f"; past the band before the move ({first.band.w_min:.4g}-{first.band.w_max:.4g} rad/s) it is kept "
                 f"only where the input excites as strongly ({band.w_min:.4g}-{band.w_max:.4g} rad/s): the move makes "
                 "a sweep's leakage past its band coherent too")
    return replace(aligned, band=band, notes=(*aligned.notes, note))


def _composite(runs: list[Record], w_min: float | None, w_max: float | None, windows: Sequence[float] | None,
               overlap: float, points_per_decade: int, coherence_threshold: float, detrend: str,
               shift: int = 0) -> FrequencyResponse:
    """:func:`frequency_response` of ``runs``, their windows' outputs moved ``shift`` samples earlier (the range,
    the windows and the whole-run low end from the runs as they are)."""
    fs = runs[0].fs
    windowed = shifted_runs(runs, shift) if shift else runs
    if not 0 <= overlap < 1:
        raise DataError(f"overlap must be in [0, 1), got {overlap:g}")
    if detrend not in ("linear", "constant", "none"):
        raise DataError(f"detrend must be 'linear', 'constant' or 'none', got {detrend!r}")
    nyquist = np.pi * fs
    given_min, given_max = w_min is not None, w_max is not None
    w_min = lowest_frequency(runs, overlap) if w_min is None else float(w_min)
    w_max = DEFAULT_TOP * nyquist if w_max is None else float(w_max)
    if not (0 < w_min < w_max) and not (given_min and given_max):
        samples = max(r.t.size for r in runs)
        raise DataError(f"the record is too short for a frequency response: its {samples} samples "
                        f"({samples / fs:.3g} s) reach down to {w_min:.4g} rad/s only, above the default top of "
                        f"{w_max:.4g} rad/s (a fifth of the Nyquist frequency {nyquist:.4g} rad/s); record longer, "
                        "or give both --wmin and --wmax")
    if not (0 < w_min < w_max):
        raise DataError(f"need 0 < w_min < w_max, got w_min = {w_min:g}, w_max = {w_max:g} rad/s")
    if w_max > nyquist * (1 + 1e-6):
        raise DataError(f"w_max = {w_max:.8g} rad/s is above the Nyquist frequency {nyquist:.8g} rad/s "
                        f"(sample rate {fs:g} Hz)")
    w_max = min(w_max, nyquist)  # pi fs typed to a few digits (3141.592654 for 1 kHz) is the Nyquist frequency
    check_length(runs, w_min, overlap)
    if windows is None:
        lengths = default_windows(w_min, longest=required_window(lowest_frequency(runs, overlap)) * (1 - 1e-9))
        # near Nyquist the shortest default windows would hold fewer than 8 samples: lengthen them (and merge)
        lengths = tuple(dict.fromkeys(max(float(x), 8.0 / fs) for x in lengths))
    else:
        lengths = tuple(windows)
    longest_run = max(r.n for r in windowed)  # the moved outputs shorten the runs by the shift
    if shift and windows is None:  # a default window as long as a run: as long as the shortened run
        lengths = tuple(dict.fromkeys(min(float(x), longest_run / fs) for x in lengths))
    grid = log_grid(w_min, w_max, points_per_decade)
    results = []
    for length in lengths:
        nseg = round(float(length) * fs)
        if nseg < 8 or nseg > longest_run:
            raise DataError(f"window {length:g} s must hold at least 8 samples and fit in the longest run "
                            f"({longest_run / fs:.4g} s)")
        results.append(window_spectra(windowed, fs, nseg, overlap, grid, detrend))
    gxx, gyy, gxy, n_d = combine_windows(results, grid)
    coh = coherence_from_spectra(gxx, gyy, gxy)
    gxy = gxy * np.exp(-1j * grid * shift / fs)  # the delay the windows' outputs were moved by, back in the phase
    with np.errstate(divide="ignore", invalid="ignore"):
        H = gxy / gxx
    err = random_error(coh, n_d)
    from synth.ident.whole_run import at_rest

    rest = all(at_rest(r) for r in runs)
    H, err, low_note = _whole_run_low_end(runs, rest, grid, H, err, gyy, coh, max(lengths))
    H, err, coh, n_d, leak_note = _resonance_from_whole_runs(runs, rest, results, grid, H, err, coh, n_d,
                                                             coherence_threshold)
    low_note = "; ".join(n for n in (low_note, leak_note) if n) or None
    level = excitation_level(results, grid, gxx, windowed)
    band = trim_to_excitation(coherent_band(grid, coh, coherence_threshold), grid, level)
    above = None
    if not given_max:
        # as dense as the grid's top cell (in rad/s) up to the cap: a lightly damped peak located within a cell
        dense = int(np.ceil(points_per_decade * LOOK_AHEAD_CAP / DEFAULT_TOP))
        ext = log_grid(w_max, LOOK_AHEAD_CAP * nyquist, dense)[1:]
        spectra = combine_windows([window_spectra(windowed, fs, round(float(x) * fs), overlap, ext, detrend)
                                   for x in lengths], ext)
        above = _above_default_top(grid, gxx, gxy, coh, band, ext, *spectra[:3], coherence_threshold)
    notes = ((_above_note(above, nyquist),) if above else ()) + ((low_note,) if low_note else ())
    return FrequencyResponse(grid, H, coh, err, n_d, gxx, gyy, gxy, band, tuple(float(x) for x in lengths),
                             "measured", runs[0].input.label(), runs[0].output.label(),
                             tuple(r.source for r in runs), notes=notes, above_default_top=above)


LRM_ERROR_LIMIT = 3.0
"""Where the local rational method's random error is more than this many times the composite's, the composite
stays: a sweep's transform is smooth in frequency, like a transient, and where little input reaches a frequency
the two cannot be told apart (a linear 0.1-5 Hz sweep of 60 s with 1 % noise: |H| 5-28 times the truth at
0.7-2.3 rad/s, random errors of 37-150 %; the composite within 1 dB there)."""


def _whole_run_low_end(runs: list[Record], rest: bool, grid: np.ndarray, H: np.ndarray, err: np.ndarray,
                       gyy: np.ndarray, coh: np.ndarray, longest: float) -> tuple[np.ndarray, np.ndarray, str | None]:
    """``H`` and its random error with the points below :data:`~synth.ident.whole_run.WHOLE_RUN_PERIODS` periods of
    the longest window taken from the whole runs (and a note saying so): the ratio of their transforms when every
    run starts and ends at rest, else the local rational method, which removes each run's transient."""
    from synth.ident.composite_bias import composite_bias
    from synth.ident.local_rational import HALF_WIDTH, local_rational_response
    from synth.ident.whole_run import WHOLE_RUN_PERIODS, whole_run_response

    low = grid < WHOLE_RUN_PERIODS * 2.0 * np.pi / longest
    if not np.any(low):
        return H, err, None
    H, err = np.array(H, complex), np.array(err, float)
    head = f"below {grid[low][-1]:.4g} rad/s ({WHOLE_RUN_PERIODS:g} periods of the longest window) the response is"
    H_lrm, err_lrm = local_rational_response(runs, grid[low])
    if rest:  # every run starts and ends at rest (synth.ident.whole_run.at_rest): the ratio, exact for a sweep; where
        # it scatters against the method beyond its error (a noise input's weak bins: the Silverbox's SNLS80mV, +-5 dB
        # and +-60 deg about a flat response below 1.2 rad/s), the method, which fits neighbouring bins
        gnn = np.maximum(np.nan_to_num(gyy * (1.0 - coh)), 0.0)
        H_r, err_r = whole_run_response(runs, grid[low], gnn[low])
        bias = composite_bias(H_r, err_r, H_lrm, err_lrm, np.isfinite(H_lrm))
        err_r = np.hypot(err_r, bias)
        use = np.isfinite(H_lrm) & (err_lrm < err_r)
        H[low], err[low] = np.where(use, H_lrm, H_r), np.where(use, err_lrm, err_r)
        method = "" if not use.any() else (f" (the local rational method at {int(use.sum())} of its {int(low.sum())} "
                                           "points, where the ratio scatters more, by its random error and the scatter "
                                           "its neighbours show against the method)")
        return H, err, (f"{head} the ratio of the whole runs' transforms{method}: every run starts and ends at rest, "
                        "and a window's taper biases a sweep's lowest frequencies")
    use = np.isfinite(H_lrm) & ~(err_lrm > LRM_ERROR_LIMIT * err[low])
    # the composite's error with the bias its neighbours show against the method; the method also where its error is
    # no larger than that (like against like: at a sweep's first points the method can be far off too)
    err_c = np.hypot(err[low], composite_bias(H[low], err[low], H_lrm, err_lrm, use))
    use |= np.isfinite(H_lrm) & (err_lrm <= err_c)
    H[low] = np.where(use, H_lrm, H[low])
    err[low] = np.where(use, err_lrm, err_c)
    return H, err, (f"{head} from the whole runs' transforms with each run's transient removed (the local rational "
                    f"method, {2 * HALF_WIDTH + 1} neighbouring frequencies per run) at {int(use.sum())} of its "
                    f"{int(low.sum())} points (the composite where that method's random error is over "
                    f"{LRM_ERROR_LIMIT:g} times the composite's): a run does not start and end at rest, and a "
                    "window's taper biases a sweep's lowest frequencies")


def _resonance_from_whole_runs(runs: list[Record], rest: bool, results: list[Any], grid: np.ndarray,
                               H: np.ndarray, err: np.ndarray, coh: np.ndarray, n_d: np.ndarray,
                               threshold: float) -> tuple:
    """Where every run is at rest at both ends and the windows leak at a resonance
    (:func:`synth.ident.resonance_leakage.leakage_points`): the whole-run ratio, the longest window's coherence,
    averages and noise; and a note (None where nothing changed)."""
    from synth.ident.resonance_leakage import leakage_points
    from synth.ident.whole_run import whole_run_response

    if not rest:
        return H, err, coh, n_d, None
    longest = max(results, key=lambda r: r.length)
    leak = leakage_points(results, grid, np.abs(H), threshold)  # the composite's peaks: flattened, not moved
    if not leak.any():
        return H, err, coh, n_d, None
    coh_l = coherence_from_spectra(longest.gxx, longest.gyy, longest.gxy)
    gnn = np.maximum(np.nan_to_num(longest.gyy * (1.0 - coh_l)), 0.0)
    H, err, coh, n_d = np.array(H, complex), np.array(err, float), np.array(coh, float), np.array(n_d, float)
    H[leak], whole_err = whole_run_response(runs, grid[leak], gnn[leak])
    err[leak] = np.fmax(whole_err, err[leak])  # never a smaller error than the composite claimed
    coh[leak], n_d[leak] = coh_l[leak], longest.n_d[leak]
    return H, err, coh, n_d, (f"at {int(leak.sum())} point(s) in {grid[leak][0]:.4g}-{grid[leak][-1]:.4g} rad/s a "
                              "resonance rings longer than the shorter windows (their coherence falls with their "
                              "length there: leakage, not noise): the response is the ratio of the whole runs' "
                              "transforms, the coherence the longest window's")


def _above_default_top(w: np.ndarray, gxx: np.ndarray, gxy: np.ndarray, coh: np.ndarray, band: CoherentBand,
                       ext: np.ndarray, gxx_ext: np.ndarray, gyy_ext: np.ndarray, gxy_ext: np.ndarray,
                       threshold: float) -> dict[str, float | None] | None:
    """How far above the default top ``w[-1]`` the response stays coherent and the input excited (``None``
    unless the coherent band reaches the top and goes on for at least :data:`LOOK_AHEAD_MIN_DECADES`)."""
    if ext.size == 0 or not band.found or band.w_max < w[-1]:
        return None
    w_all, gxx_all = np.r_[w, ext], np.r_[gxx, gxx_ext]
    coh_all = np.r_[coh, coherence_from_spectra(gxx_ext, gyy_ext, gxy_ext)]
    wide = trim_to_excitation(coherent_band(w_all, coh_all, threshold), w_all, gxx_all)
    if not wide.found or not wide.w_min <= w[-1] <= wide.w_max / 10 ** LOOK_AHEAD_MIN_DECADES:
        return None
    deficit = excitation_deficit(w_all, gxx_all, reference=band.contains(w_all))[w.size:]
    short = np.flatnonzero(deficit > UNDER_EXCITED_DB)
    excited_to = float(ext[short[0] - 1]) if short.size and short[0] > 0 else (
        float(w[-1]) if short.size else float(ext[-1]))
    with np.errstate(divide="ignore", invalid="ignore"):
        mag = 20.0 * np.log10(np.abs(np.r_[gxy[-1] / gxx[-1], gxy_ext / gxx_ext]))
    inside = np.r_[True, wide.contains(ext)]
    k = int(np.nanargmax(np.where(inside, mag, -np.inf)))
    peak = k > 0 and mag[k] - mag[0] >= 3.0
    return {"default_top": float(w[-1]), "coherent_to": float(wide.w_max), "excited_to": excited_to,
            "peak_w": float(ext[k - 1]) if peak else None, "peak_db": float(mag[k] - mag[0]) if peak else None}


def _above_note(above: dict[str, Any], nyquist: float) -> str:
    """The sentence for :attr:`FrequencyResponse.notes` about the data above the default top."""
    top, to = above["default_top"], above["coherent_to"]
    at_least = "at least " if to >= LOOK_AHEAD_CAP * nyquist * (1 - 1e-9) else ""
    peak = (f"; the measured |H| peaks there at {above['peak_w']:.4g} rad/s, {above['peak_db']:+.1f} dB over its "
            f"value at {top:.4g} rad/s (a resonance above the default range?)" if above["peak_w"] is not None else "")
    return (f"the coherent band reaches the default upper limit {top:.4g} rad/s (a fifth of the Nyquist frequency "
            f"{nyquist:.4g} rad/s) and goes on: the input excites up to {above['excited_to']:.4g} rad/s and the "
            f"response stays coherent up to {at_least}{to:.4g} rad/s{peak}; pass --wmax {to:.4g} to see above")


def rate_to_attitude(resp: FrequencyResponse) -> FrequencyResponse:
    """Integrate a rate response to an attitude response: ``H / (j w)``.

    Magnitude drops by ``20 log10 w`` dB, phase by 90 deg; coherence and random
    error are unchanged (the seed, fig. 11: ``theta = p / s``).

    Examples
    --------
    >>> from synth.ident.coherence import coherent_band
    >>> w = np.array([2.0]); b = coherent_band(np.r_[w, 3.0], np.ones(2))
    >>> r = FrequencyResponse(w, np.array([4.0 + 0j]), np.ones(1), np.zeros(1), np.ones(1),
    ...                       np.ones(1), np.ones(1), np.ones(1, complex), b, (10.0,))
    >>> a = rate_to_attitude(r); complex(a.H[0]), a.kind
    (-2j, 'integrated (1/s)')
    """
    return replace(resp, H=resp.H / (1j * resp.w), gxy=resp.gxy / (1j * resp.w), gyy=resp.gyy / resp.w ** 2,
                   kind="integrated (1/s)")


def correct_response(resp: FrequencyResponse, divide_by: Any = None, skew: float = 0.0) -> FrequencyResponse:
    """Remove known sensor/filter dynamics and a channel time skew from a measured response.

    The NASA report (sec. 2, 4.2) asks for the sensors' and filters' dynamics to be
    known "so that their effect can be incorporated", and its recorder skewed adjacent
    channels by up to 15 ms. Here ``H`` and ``Gxy`` are divided by ``divide_by(jw)``
    (``Gyy`` by its squared magnitude) and multiplied by ``exp(+j w skew)``; the
    coherence and random error do not change.

    Parameters
    ----------
    resp : FrequencyResponse
    divide_by : Plant, optional
        The known dynamics between the true output and the recorded one (a sensor, an
        anti-aliasing filter), with its delay if it has one.
    skew : float
        How much the output channel lags the input channel [s]: the recorded output is
        ``y(t - skew)``, so the measured response carries an extra phase lag ``w skew``
        (negative: the output channel leads).

    Returns
    -------
    FrequencyResponse
        With ``corrections`` saying what was removed.

    Examples
    --------
    >>> from synth.ident.coherence import coherent_band
    >>> from synth.plant import Plant
    >>> w = np.array([10.0, 20.0]); b = coherent_band(w, np.ones(2))
    >>> meas = np.exp(-1j * w * 0.015) * 50 / (1j * w + 50)       # a 50 rad/s filter and a 15 ms skew
    >>> r = FrequencyResponse(w, meas, np.ones(2), np.zeros(2), np.ones(2), np.ones(2), np.ones(2), meas, b, (1.0,))
    >>> c = correct_response(r, Plant.from_string("50/(s+50)"), skew=0.015)
    >>> np.round(c.H, 12).tolist(), c.corrections[1]
    ([(1+0j), (1+0j)], 'output channel skew 0.015 s removed (phase + w * 0.015 s)')
    """
    if not np.isfinite(skew):
        raise DataError(f"skew must be a finite number of seconds, got {skew!r}")
    factor = np.exp(1j * resp.w * skew)
    notes = list(resp.corrections)
    gyy = resp.gyy
    if divide_by is not None:
        F = np.asarray(divide_by.freqresp(resp.w), complex)
        if not np.all(np.isfinite(F)) or np.any(np.abs(F) == 0):
            raise DataError(f"the correction {divide_by.to_string()} is zero or infinite inside "
                            f"{resp.w[0]:.4g}-{resp.w[-1]:.4g} rad/s")
        factor = factor / F
        gyy = gyy / np.abs(F) ** 2
        notes.append(f"divided by {divide_by.to_string()} (known sensor/filter dynamics)")
    if skew:
        notes.append(f"output channel skew {skew:g} s removed (phase + w * {skew:g} s)")
    return replace(resp, H=resp.H * factor, gxy=resp.gxy * factor, gyy=gyy, corrections=tuple(notes))
