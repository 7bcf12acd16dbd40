"""An option's value that starts with "-" (a negative gain, a transfer function with a minus sign) was taken by
argparse for another option: ``synth hq --tf "-2/(s+1)"`` ended in "argument --tf: expected one argument"."""

from __future__ import annotations


def test_a_negative_transfer_function_is_the_value_of_tf(run_cli):
    r = run_cli("hq", "--tf", "-2/(s+1)")
    assert r.code == 0, r.err
    assert "low-frequency gain is negative" in r.out and r.out.startswith("-2/(s+1)")


def test_a_negative_controller_reaches_the_controller_parser(run_cli):
    r = run_cli("check", "specs/x4_rotor.yaml", "--controller", "-3", "-q")
    assert r.code == 2 and "cannot parse controller '-3'" in r.err and len(r.err.strip().splitlines()) == 1


def test_an_option_after_a_value_taking_option_is_not_swallowed(run_cli):
    r = run_cli("check", "specs/x4_rotor.yaml", "--controller", "-q")
    assert r.code == 2 and "argument --controller/-c: expected one argument" in r.err
