"""Outputs are staged and moved into place at the end; a refusal or a failure leaves nothing behind."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import pytest

from synth.errors import OutputExistsError
from synth.figure_files import save_figure
from synth.outputs import MANIFEST, OutputDir, dump_json, written_by_synth


def _listing(root: Path) -> list[str]:
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


def test_nothing_is_in_place_before_commit_and_everything_after(tmp_path):
    out = OutputDir(tmp_path / "rep")
    a = out.claim("result.json")
    a.write_text(dump_json({"x": 1}))
    b = out.claim("figs/one.png")
    save_figure(plt.subplots()[0], b)
    assert not (tmp_path / "rep").exists()
    out.commit()
    assert _listing(tmp_path) == ["rep", f"rep/{MANIFEST}", "rep/figs", "rep/figs/one.png", "rep/result.json"]
    assert out.final(a).read_text() == dump_json({"x": 1})


def test_a_refused_commit_moves_nothing_and_leaves_no_staging(tmp_path):
    (tmp_path / "rep").mkdir()
    (tmp_path / "rep" / "report.html").write_text("<p>my own notes</p>")
    out = OutputDir(tmp_path / "rep")
    out.claim("result.json").write_text(dump_json({}))
    out.written.append("report.html")  # a name that clashes, found only at the end
    (out.staging / "report.html").write_text("synth's")
    with pytest.raises(OutputExistsError, match=r"report\.html: exists and was not written by synth"):
        out.commit()
    assert _listing(tmp_path) == ["rep", "rep/report.html"]
    assert (tmp_path / "rep" / "report.html").read_text() == "<p>my own notes</p>"


def test_expected_names_are_refused_before_any_work(tmp_path):
    (tmp_path / "rep").mkdir()
    (tmp_path / "rep" / "report.html").write_text("mine")
    with pytest.raises(OutputExistsError, match="not overwriting"):
        OutputDir(tmp_path / "rep", expect=["result.json", "report.html"])
    assert _listing(tmp_path) == ["rep", "rep/report.html"]
    OutputDir(tmp_path / "rep", force=True, expect=["report.html"])  # --force accepts it


def test_an_exception_before_commit_leaves_nothing(tmp_path):
    def failing_writer():
        out = OutputDir(tmp_path / "rep")
        out.claim("a.json").write_text("{}")
        raise RuntimeError("solver crashed")

    with pytest.raises(RuntimeError):
        failing_writer()
    import gc

    gc.collect()
    assert _listing(tmp_path) == []


def test_own_outputs_are_recognized_by_content_without_the_manifest(tmp_path):
    out = OutputDir(tmp_path / "rep")
    out.claim("result.json").write_text(dump_json({"a": 1}))
    out.claim("report.html").write_text('<html><head><meta name="generator" content="synth 0.1.0"></head></html>')
    save_figure(plt.subplots()[0], out.claim("fig.png"))
    out.commit()
    (tmp_path / "rep" / MANIFEST).unlink()
    for name in ("result.json", "report.html", "fig.png"):
        assert written_by_synth(tmp_path / "rep" / name), name
    OutputDir(tmp_path / "rep", expect=["result.json", "report.html", "fig.png"])  # no refusal
    (tmp_path / "rep" / "user.png").write_bytes(b"\x89PNG\r\n\x1a\n not ours")
    assert not written_by_synth(tmp_path / "rep" / "user.png")


def test_a_folder_that_cannot_be_created_is_refused_at_once(tmp_path):
    (tmp_path / "afile").write_text("x")
    with pytest.raises(OutputExistsError, match="cannot write here"):
        OutputDir(tmp_path / "afile" / "rep")


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc (a folder nothing can be made in)")
def test_a_folder_nothing_can_be_made_in_is_refused_whatever_its_permission_bits_say(tmp_path):
    # /proc's bits say writable to root, yet mkdir there fails: synth used to find out only when it wrote the
    # report, after the design, with a traceback
    with pytest.raises(OutputExistsError, match=r"cannot write here \(/proc is not a writable folder\)"):
        OutputDir(Path("/proc/synth-report"))
    with pytest.raises(OutputExistsError, match="cannot write here"):
        OutputDir(Path("/proc/synth/deeper/report"))
    OutputDir(tmp_path / "new" / "report")  # a folder that can be made: no refusal, and nothing left behind
    assert list(tmp_path.iterdir()) == []


def test_a_file_where_the_folder_should_be_is_refused(tmp_path):
    (tmp_path / "rep").write_text("x")
    with pytest.raises(OutputExistsError, match="not a directory"):
        OutputDir(tmp_path / "rep")


def test_a_file_synth_wrote_and_the_user_changed_is_not_overwritten(tmp_path):
    """A black-box helper edited identify.json by hand and re-ran identify: it was replaced without a word (the
    manifest held names only). The manifest now holds each file's SHA-256 as written."""
    folder = tmp_path / "out"
    first = OutputDir(folder)
    first.claim("result.json").write_text('{"generator": "synth", "x": 1}\n')
    first.commit()
    again = OutputDir(folder, expect=["result.json"])  # unchanged: regenerated freely
    again.claim("result.json").write_text('{"generator": "synth", "x": 2}\n')
    again.commit()
    assert (folder / "result.json").read_text() == '{"generator": "synth", "x": 2}\n'
    (folder / "result.json").write_text('{"generator": "synth", "x": 2, "my note": "keep"}\n')
    with pytest.raises(OutputExistsError, match=r"result\.json: was written by synth and changed since"):
        OutputDir(folder, expect=["result.json"])
    forced = OutputDir(folder, force=True, expect=["result.json"])
    forced.claim("result.json").write_text('{"generator": "synth", "x": 3}\n')
    forced.commit()
    assert (folder / "result.json").read_text() == '{"generator": "synth", "x": 3}\n'
    assert '"sha256"' in (folder / MANIFEST).read_text()
