"""The compiled kernels' disk cache never runs an old compilation of code that changed in another module.

numba stamps a cached function with its own file only: the loop kernel (``synth/sim/_kernel.py``) inlines the
block equations of ``synth/sim/_steps.py``, and an edited block would run from the stale cache.
:func:`synth.jit.jit` stamps every entry with its whole package. The test builds a package with the same
layout, changes the called function (same size, newer time) and runs it again in a fresh process.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytest.importorskip("numba")

ROOT = Path(__file__).resolve().parents[1]

CALLER = textwrap.dedent("""
    from synth.jit import jit
    from kernels.callee import scale

    @jit
    def run(x):
        return scale(x) + 1.0
""")

CALLEE = textwrap.dedent("""
    from synth.jit import jit

    @jit(inline="always")
    def scale(x):
        return {factor} * x
""")


def _run(folder: Path) -> float:
    code = "from kernels.caller import run; print(run(2.0))"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(folder), str(ROOT)])}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.strip())


def test_a_changed_callee_in_another_module_is_recompiled(tmp_path: Path) -> None:
    package = tmp_path / "kernels"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "caller.py").write_text(CALLER)
    callee = package / "callee.py"
    callee.write_text(CALLEE.format(factor="2.0"))
    assert _run(tmp_path) == 5.0
    assert list((package / "__pycache__").glob("caller.run-*.nbi")), "the caller was not cached"
    stat = callee.stat()
    callee.write_text(CALLEE.format(factor="3.0"))  # the same size: only the time tells
    os.utime(callee, (stat.st_atime + 10, stat.st_mtime + 10))
    assert _run(tmp_path) == 7.0  # numba's own stamp alone: 5.0, the caller's old compilation
