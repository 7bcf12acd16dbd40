"""A record named without ``--data`` (session 73): ``synth identify log.csv``, what a new user types first, was
refused with argparse's bare "unrecognized arguments: log.csv"; the one line now says how to give it."""

from __future__ import annotations

import pytest


@pytest.mark.parametrize("command", ["identify", "diagnose", "psd"])
def test_a_file_name_without_data_gets_the_option_in_its_one_line(run_cli, tmp_path, command):
    res = run_cli(command, str(tmp_path / "log.csv"), *(["--plant", "1/(s+1)"] if command == "diagnose" else []),
                  *(["--signal", "y"] if command == "psd" else []))
    assert res.code == 2
    lines = [line for line in res.err.splitlines() if "error" in line]
    assert len(lines) == 1, res.err
    if command == "identify":  # --data is optional there (--x4-demo): the name is the only thing wrong
        assert f"(a record is given with --data: synth identify --data {tmp_path / 'log.csv'})" in lines[0], lines
    else:  # --data is required: argparse names it before it looks at the rest
        assert "--data" in lines[0], lines


def test_an_extra_argument_with_data_given_gets_no_hint(run_cli, tmp_path):
    res = run_cli("identify", "--data", str(tmp_path / "a.csv"), str(tmp_path / "b.csv"))
    assert res.code == 2
    assert res.err.strip().endswith(f"unrecognized arguments: {tmp_path / 'b.csv'}"), res.err
