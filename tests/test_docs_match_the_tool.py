"""What the user documentation states matches the tool (a black-box test found both wrong): the README's command
table gives each command's exit codes as its own ``--help`` does (``tradeoff`` was "0 done, 2 bad input" while it
exits 1 when no point is feasible; ``identify``, ``simulate`` and ``diagnose`` missed codes they use), and
docs/spec-format.md has a row for every requirement type (``peak_control_sensitivity`` had none)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from synth.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
COMMANDS = ["check", "design", "simulate", "tradeoff", "identify", "freqresp", "hq", "sweep-design", "psd",
            "diagnose"]


def _codes(text: str) -> set[str]:
    """The exit codes a text lists: numbers at the start of its comma-separated items (``128 + ...`` as 128)."""
    return {m.group(1) for m in re.finditer(r"(?:^|[,:(]\s*)(\d+)\s+(?=[a-z+])", text)}


@pytest.mark.parametrize("command", COMMANDS)
def test_the_readme_lists_the_exit_codes_the_help_lists(command: str) -> None:
    sub = build_parser()._subparsers._group_actions[0].choices[command]  # type: ignore[union-attr]
    described = sub.description or ""
    helped = described[described.lower().index("exit codes:") + len("exit codes:"):]
    rows = [line for line in (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
            if line.startswith(f"| `synth {command} ")]
    assert len(rows) == 1, command
    assert _codes(rows[0].rsplit("|", 2)[1]) == _codes(helped), (rows[0].rsplit("|", 2)[1], helped)


def test_every_requirement_type_has_a_row_in_the_spec_format_table() -> None:
    """``peak_control_sensitivity`` was accepted by every spec but had no row (a black-box test found it)."""
    from synth.requirements import REQUIREMENT_TYPES

    rows = {line.split("`")[1] for line in (ROOT / "docs" / "spec-format.md").read_text(encoding="utf-8").splitlines()
            if line.startswith("| `")}
    assert sorted(set(REQUIREMENT_TYPES) - rows) == []
