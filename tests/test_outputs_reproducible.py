"""The README's main job gives byte-identical files run after run, and the committed report's content.

Two runs on one machine write the same bytes. Against the committed report (written on whatever machine made
the last commit) the files are compared by content: OpenBLAS picks its kernels per CPU (AVX2, AVX-512, ...),
which moves the identification's converged parameters in their 8th significant digit, and the committed copy
then differs in those digits and in a few pixels drawn at sub-pixel positions. Text must agree exactly but for
numbers, numbers to 1e-6 relative (1e-9 absolute), images pixel for pixel but for at most 0.1 % of the pixels by one level.
"""

from __future__ import annotations

import io
import json
import re
from contextlib import redirect_stdout
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from synth.cli import main

ROOT = Path(__file__).resolve().parent.parent
SPEC = "specs/x4_rotor_from_data.yaml"
COMMITTED = ROOT / "reports" / "x4_rotor_from_data"


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_the_main_job_twice_gives_the_same_bytes_as_the_committed_report(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    out = tmp_path / "report"
    runs = []
    for _ in range(2):  # into the same folder: the second run replaces synth's own files
        with redirect_stdout(io.StringIO()):
            assert main(["design", SPEC, "--out", str(out), "--quiet"]) == 0
        runs.append(_files(out))
    assert runs[0].keys() == runs[1].keys()
    differ = [name for name in runs[0] if runs[0][name] != runs[1][name]]
    assert not differ, f"not byte-identical between two runs: {differ}"
    assert [p.name for p in tmp_path.iterdir()] == ["report"]  # no staging folder left
    committed = _files(COMMITTED)
    fresh = {k: v.replace(f" --out {out}".encode(), b"") for k, v in runs[1].items()}  # the command shown
    assert sorted(committed) == sorted(fresh)
    stale = sorted(name for name in committed if not same_content(name, committed[name], fresh[name]))
    assert not stale, (f"reports/x4_rotor_from_data differs from what `synth design {SPEC}` writes: {stale}; "
                       f"regenerate it with that command and commit it")


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _same_text(a: str, b: str) -> bool:
    """Equal but for numbers, which agree to 1e-6 relative (or in their last printed digit)."""
    if _NUMBER.split(a) != _NUMBER.split(b):
        return False
    for x, y in zip(_NUMBER.findall(a), _NUMBER.findall(b)):
        if x != y and not _close(float(x), float(y), _last_digit(x) + _last_digit(y)):
            return False
    return True


def _last_digit(text: str) -> float:
    mantissa, _, exponent = text.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (int(exponent or 0) - decimals)


def _close(x: float, y: float, digit: float = 0.0) -> bool:
    return abs(x - y) <= max(1e-6 * max(abs(x), abs(y)), 1e-9, digit)


def _same_json(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same_json(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same_json(x, y) for x, y in zip(a, b))
    if isinstance(a, bool) or isinstance(b, bool) or a is None or b is None:
        return a == b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return a == b or _close(float(a), float(b))
    if isinstance(a, str) and isinstance(b, str):
        return _same_text(a, b)
    return False


def _same_image(a: bytes, b: bytes) -> bool:
    from matplotlib.image import imread

    x, y = imread(io.BytesIO(a)), imread(io.BytesIO(b))
    if x.shape != y.shape:
        return False
    levels = np.round(np.abs(x - y).max(axis=-1) * 255)
    return levels.max() <= 1 and np.count_nonzero(levels) <= 1e-3 * levels.size


def same_content(name: str, a: bytes, b: bytes) -> bool:
    """Whether two versions of a report file say the same (see the module's docstring)."""
    if a == b:
        return True
    if name.endswith(".png"):
        return _same_image(a, b)
    if name.endswith(".json"):
        return _same_json(json.loads(a), json.loads(b))
    return _same_text(a.decode("utf-8"), b.decode("utf-8"))


@pytest.mark.parametrize(("name", "a", "b", "same"), [
    ("r.json", b'{"kp": 3.65879497462, "m": "C(0) = 3.659"}', b'{"kp": 3.65879492864, "m": "C(0) = 3.659"}', True),
    ("r.json", b'{"kp": 3.6587}', b'{"kp": 3.6588}', False),
    ("r.json", b'{"m": "met"}', b'{"m": "NOT met"}', False),
    ("r.json", b'{"kp": 3.0, "ki": 1.0}', b'{"kp": 3.0}', False),
    ("r.html", b"<td>473.3 rad/s</td>", b"<td>473.4 rad/s</td>", True),  # a rounding straddle in the last digit
    ("r.html", b"<td>473.3 rad/s</td>", b"<td>472.3 rad/s</td>", False),
    ("r.html", b"<td>473.3 rad/s</td>", b"<td>473.3 rad</td>", False),
])
def test_the_content_comparison_tells_float_noise_from_a_change(name: str, a: bytes, b: bytes, same: bool) -> None:
    assert same_content(name, a, b) is same


def test_an_image_with_a_moved_curve_is_a_change(tmp_path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def png(shift: float) -> bytes:
        fig, ax = plt.subplots(figsize=(4, 3), dpi=50)
        x = np.linspace(0, 1, 50)
        ax.plot(x, x + shift)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", metadata={"Software": None})
        plt.close(fig)
        return buf.getvalue()

    assert same_content("f.png", png(0.0), png(0.0))
    assert not same_content("f.png", png(0.0), png(0.2))
