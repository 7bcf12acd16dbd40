"""Every command that writes a report folder or a --json file checks it before computing.

A user's file of the same name -> exit 2 with one line, no computation started, nothing written; after the user
removes it the next run succeeds; rerunning over synth's own outputs succeeds.
"""

from __future__ import annotations

import io
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from synth.cli import main

SPEC = """name: tiny
plant: {tf: "2/(s+1)"}
controller: {type: P, bounds: {kp: [0.01, 20]}}
requirements:
  - {type: peak_sensitivity, max_db: 6}
"""


def _run(argv: list[str]) -> tuple[int, str]:
    err = io.StringIO()
    with redirect_stdout(io.StringIO()), redirect_stderr(err):
        code = main(argv)
    return code, err.getvalue()


def _listing(root: Path) -> list[str]:
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("inputs")
    (root / "tiny.yaml").write_text(SPEC)
    t = np.arange(0, 20, 0.01)
    u = np.where((t % 4) >= 2, 1.0, 0.0)
    y = 2 * (1 - np.exp(-np.minimum(t % 2, 2)))  # crude, only read and fitted
    rng = np.random.default_rng(0)
    y = np.where(u > 0, y, 2 - y) + 0.01 * rng.normal(size=t.size)
    np.savetxt(root / "step.csv", np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    chirp = np.sin(2 * np.pi * (0.05 + 0.05 * t) * t)
    from scipy.signal import lfilter

    resp = lfilter([0.02], [1, -0.98], chirp) + 0.001 * rng.normal(size=t.size)
    np.savetxt(root / "chirp.csv", np.c_[t, chirp, resp], delimiter=",", header="t,u,y", comments="")
    np.savetxt(root / "dist.csv", np.c_[t, rng.normal(size=t.size)], delimiter=",", header="t,d", comments="")
    return root


def _cases(inputs: Path, out: Path) -> dict[str, tuple[list[str], str, str]]:
    """command -> (argv, the report file a user might have there, the computation that must not start)."""
    spec, step, chirp, dist = (str(inputs / n) for n in ("tiny.yaml", "step.csv", "chirp.csv", "dist.csv"))
    o = str(out)
    return {
        "design": (["design", spec, "--out", o], "report.html", "synth.spec.load_spec"),
        "tradeoff": (["tradeoff", spec, "--sweep", "requirements.peak_sensitivity.max_db=6:6:1", "--workers", "1",
                      "--out", o, "--quiet"], "tradeoff.html", "synth.spec.load_spec"),
        "simulate": (["simulate", spec, "--controller", "P(1)", "--horizon", "2", "--step-time", "0.1", "--out", o,
                      "--quiet"], "metrics.json", "synth.spec.load_spec"),
        "identify": (["identify", "--data", step, "--structure", "k/(s+p)", "--delay", "0", "--out", o, "--quiet",
                      "--no-figures"], "identify.json", "synth.data.load_record"),
        "freqresp": (["freqresp", "--data", chirp, "--out", o, "--quiet"], "result.json", "synth.data.load_record"),
        "psd": (["psd", "--data", dist, "--time", "t", "--signal", "d", "--out", o, "--json", str(out / "x.json")],
                "psd.json", "synth.data.disturbance.load_disturbance"),
        "hq": (["hq", "--tf", "4/(s^2+2*s+4)", "--out", o], "hq.json", "synth.ident.hq.hq_from_plant"),
        "diagnose": (["diagnose", "--plant", "2/(s+1)", "--data", step, "--time", "t", "--input", "u", "--output", "y",
                      "--candidates", "delay", "--out", o, "--quiet"], "report.html", "synth.gap.diagnose.load_model"),
    }


def _forbid(monkeypatch, target: str) -> None:
    module, name = target.rsplit(".", 1)

    def computed(*args, **kwargs):
        raise AssertionError(f"{target} ran although the output was refused")

    monkeypatch.setattr(f"{module}.{name}", computed)


COMMANDS = ["design", "tradeoff", "simulate", "identify", "freqresp", "psd", "hq", "diagnose"]


@pytest.mark.parametrize("command", COMMANDS)
def test_a_users_file_is_refused_before_computing_and_the_folder_is_reusable(command, inputs, tmp_path, monkeypatch):
    out = tmp_path / "rep"
    argv, users_file, first_computation = _cases(inputs, out)[command]
    out.mkdir()
    (out / users_file).write_text("my own notes")
    with monkeypatch.context() as m:
        _forbid(m, first_computation)
        code, err = _run(argv)
    assert code == 2, err
    assert err.count("\n") == 1 and "not written by synth" in err and users_file in err, err
    assert _listing(tmp_path) == ["rep", f"rep/{users_file}"]  # nothing written, no staging folder
    (out / users_file).unlink()
    code, err = _run(argv)
    assert code in (0, 1), err
    first = _listing(out)
    assert users_file in [Path(p).name for p in first]
    code, err = _run(argv)  # over synth's own outputs
    assert code in (0, 1), err
    assert _listing(out) == first
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]


@pytest.mark.parametrize("command", ["check", "design"])
def test_a_users_json_file_is_refused_before_computing(command, inputs, tmp_path, monkeypatch):
    user = tmp_path / "mine.json"
    user.write_text('{"mine": true}')
    argv = [command, str(inputs / "tiny.yaml"), "--json", str(user)]
    argv += ["--controller", "P(1)"] if command == "check" else ["--no-report"]
    with monkeypatch.context() as m:
        _forbid(m, "synth.spec.load_spec")
        code, err = _run(argv)
    assert code == 2 and "not written by synth" in err and err.count("\n") == 1, err
    assert user.read_text() == '{"mine": true}'
    user.unlink()
    for _ in range(2):  # written, then replaced (synth's own)
        code, err = _run(argv)
        assert code in (0, 1), err
    assert '"generator": "synth' in user.read_text()


@pytest.mark.parametrize("command", ["design", "identify", "hq"])
def test_a_folder_synth_cannot_write_is_reported_before_computing(command, inputs, tmp_path, monkeypatch):
    (tmp_path / "afile").write_text("x")
    argv, _, first_computation = _cases(inputs, tmp_path / "afile" / "rep")[command]
    with monkeypatch.context() as m:
        _forbid(m, first_computation)
        code, err = _run(argv)
    assert code == 2 and "cannot write here" in err and err.count("\n") == 1, err
    assert _listing(tmp_path) == ["afile"]


def test_a_write_the_file_system_refuses_midway_is_one_line_and_exit_2(inputs, tmp_path, monkeypatch):
    import errno

    import synth.outputs

    target = tmp_path / "out.json"

    def full(path, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(synth.outputs, "write_json", full)
    code, err = _run(["design", str(inputs / "tiny.yaml"), "--no-report", "--json", str(target)])
    assert code == 2 and err == f"synth design: error: {target}: No space left on device\n", err
    assert not target.exists()
