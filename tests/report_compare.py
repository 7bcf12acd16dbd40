"""Whether two versions of a report file say the same, for a committed report made on another machine.

Two runs on one machine write the same bytes (tests/test_outputs_reproducible.py, tests/test_forked.py). The
committed report was written on whatever machine made the last commit: OpenBLAS picks its kernels per CPU (AVX2,
AVX-512, ...), which moves an identification's converged parameters in their 8th significant digit (seen: kp
3.65879497462 on one machine, 3.65879492864 on an AVX2 one), and the committed copy then differs in those digits
and in a few pixels drawn at sub-pixel positions. So text must agree exactly but for numbers, numbers to 1e-6
relative (1e-9 absolute, or one unit of their last printed digit: a time on a 1 ms grid may move by one sample),
images pixel for pixel, each against the closest of the other's pixel and its neighbours (an axes edge whose
position lies on a pixel boundary snaps to either side: a spine seen one pixel to the right), but for at most 0.1 %
of the pixels by one 8-bit level, of which at most 0.01 % by more.
"""

from __future__ import annotations

import io
import json
import re
from typing import Any

import numpy as np

__all__ = ["same_content"]

_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _same_text(a: str, b: str) -> bool:
    """Equal but for numbers, which agree to 1e-6 relative, or by one unit of the last printed digit when they
    have a fraction or an exponent (a rounding straddle); integers (counts) must be equal."""
    if _NUMBER.split(a) != _NUMBER.split(b):
        return False
    for x, y in zip(_NUMBER.findall(a), _NUMBER.findall(b)):
        if x != y and not _close(float(x), float(y), max(_last_digit(x), _last_digit(y))):
            return False
    return True


def _last_digit(text: str) -> float:
    """One unit of the last printed digit of a number with a fraction or an exponent; 0 for an integer."""
    mantissa, _, exponent = text.lower().partition("e")
    if "." not in mantissa and not exponent:
        return 0.0
    decimals = len(mantissa.partition(".")[2])
    return 1.0000001 * 10.0 ** (int(exponent or 0) - decimals)


def _close(x: float, y: float, digit: float = 0.0) -> bool:
    return abs(x - y) <= max(1e-6 * max(abs(x), abs(y)), 1e-9, digit)


def _same_json(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same_json(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same_json(x, y) for x, y in zip(a, b))
    if isinstance(a, bool) or isinstance(b, bool) or a is None or b is None:
        return a == b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):  # as in text: repr is the printed form
        return a == b or _close(float(a), float(b), max(_last_digit(repr(a)), _last_digit(repr(b))))
    if isinstance(a, str) and isinstance(b, str):
        return _same_text(a, b)
    return False


def _same_image(a: bytes, b: bytes) -> bool:
    from matplotlib.image import imread

    x, y = imread(io.BytesIO(a)), imread(io.BytesIO(b))
    if x.shape != y.shape:
        return False
    levels = np.maximum(_nearest_levels(x, y), _nearest_levels(y, x))
    return np.count_nonzero(levels) <= 1e-3 * levels.size and np.count_nonzero(levels > 1) <= 1e-4 * levels.size


def _nearest_levels(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Each pixel of ``x`` against the closest of ``y``'s pixel and its 8 neighbours, in 8-bit levels: an edge that
    snapped to the next pixel (a spine whose position lies on a pixel boundary) counts as the same drawing."""
    h, w = x.shape[:2]
    padded = np.pad(y, ((1, 1), (1, 1), (0, 0)), mode="edge")
    best = np.full((h, w), np.inf)
    for dy in range(3):
        for dx in range(3):
            best = np.minimum(best, np.abs(x - padded[dy:dy + h, dx:dx + w]).max(axis=-1))
    return np.round(best * 255)


def same_content(name: str, a: bytes, b: bytes) -> bool:
    """Whether two versions of a report file say the same (see the module's docstring)."""
    if a == b:
        return True
    if name == ".synth-manifest.json":  # its hashes are of the files, which are compared as above
        x, y = json.loads(a), json.loads(b)
        return x.get("files") == y.get("files") and x.get("generator") == y.get("generator")
    if name.endswith(".png"):
        return _same_image(a, b)
    if name.endswith(".json"):
        return _same_json(json.loads(a), json.loads(b))
    return _same_text(a.decode("utf-8"), b.decode("utf-8"))
