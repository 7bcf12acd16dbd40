"""The README's main job gives byte-identical files run after run, and the committed report's content (compared
as tests/report_compare.py explains: the committed copy may come from a machine with another CPU)."""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from synth.cli import main
from tests.report_compare import same_content

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


@pytest.mark.parametrize(("name", "a", "b", "same"), [
    ("r.json", b'{"kp": 3.65879497462, "m": "C(0) = 3.659"}', b'{"kp": 3.65879492864, "m": "C(0) = 3.659"}', True),
    ("r.json", b'{"kp": 3.6587}', b'{"kp": 3.6589}', False),
    ("r.json", b'{"settling_time": 0.943}', b'{"settling_time": 0.944}', True),  # one sample of 1 ms
    ("r.json", b'{"settling_time": 0.943}', b'{"settling_time": 0.945}', False),
    ("r.json", b'{"m": "met"}', b'{"m": "NOT met"}', False),
    ("r.json", b'{"kp": 3.0, "ki": 1.0}', b'{"kp": 3.0}', False),
    ("r.html", b"<td>473.3 rad/s</td>", b"<td>473.4 rad/s</td>", True),  # a rounding straddle in the last digit
    ("r.html", b"<td>473.3 rad/s</td>", b"<td>472.3 rad/s</td>", False),
    ("r.html", b"<td>473.3 rad/s</td>", b"<td>473.3 rad</td>", False),
    ("r.html", b"meets all 3 requirements", b"meets all 4 requirements", False),
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



def test_an_image_with_one_digit_changed_is_a_change_and_a_spine_one_pixel_over_is_not() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def png(label: str) -> bytes:
        fig, ax = plt.subplots(figsize=(8, 6), dpi=110)
        x = np.linspace(0, 1, 50)
        ax.plot(x, x, label=label)
        ax.legend()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", metadata={"Software": None})
        plt.close(fig)
        return buf.getvalue()

    def spine(column: int) -> bytes:  # a white 600 x 800 image with a black vertical line, 2 pixels wide
        img = np.ones((600, 800, 3))
        img[40:560, column:column + 2] = 0.0
        buf = io.BytesIO()
        plt.imsave(buf, img, format="png")
        return buf.getvalue()

    assert not same_content("f.png", png("peaks at 1354"), png("peaks at 1355"))
    assert same_content("f.png", spine(500), spine(501))  # snapped to the next pixel
    assert not same_content("f.png", spine(500), spine(503))
