"""The README's main job gives byte-identical files run after run, and the same files as the committed report
(so `git status` stays clean after the quickstart)."""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from pathlib import Path

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
    stale = sorted(name for name in committed.keys() | fresh.keys() if committed.get(name) != fresh.get(name))
    assert not stale, (f"reports/x4_rotor_from_data differs from what `synth design {SPEC}` writes: {stale}; "
                       f"regenerate it with that command and commit it")
