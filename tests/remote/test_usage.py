"""The remote commands' usage: every option in ``--help``, and the options a remote run does
not take are one-line usage errors (exit 2) before anything connects (no server here)."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from dial.cli import build_parser, main

# DESIGN.md 6.4's interface, option by option.
DESIGNED = {
    "serve": [
        "--scene", "--listen", "--token-file", "--watchdog", "--pace", "--perturb", "--seed",
        "--disturb", "--log",
    ],
    "link": ["--listen", "--to", "SPEC"],
    "run": ["--remote", "--token-file", "--split", "--link", "--lead", "--diverge", "--record",
            "--rerun", "--no-predict"],
}  # fmt: skip
NOWHERE = "ws://127.0.0.1:9"  # nothing listens on the discard port: no test may connect


def _subparser(name: str) -> argparse.ArgumentParser:
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    parser = sub.choices[name]  # type: ignore[index]
    assert isinstance(parser, argparse.ArgumentParser)
    return parser


@pytest.mark.parametrize("name", list(DESIGNED))
def test_help_lists_every_option_with_its_meaning(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as info:
        main([name, "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    for action in _subparser(name)._actions:
        assert action.help and action.help != argparse.SUPPRESS, action.dest
        for flag in action.option_strings or [str(action.metavar or action.dest)]:
            assert flag in out, flag
    for flag in DESIGNED[name]:
        assert flag in out, flag


@pytest.mark.parametrize(
    ("extra", "said"),
    [
        (["--seed", "3"], "--seed: not with --remote (the robot's world is perturbed"),
        (["--disturb", "push body=hand_base force=0,300,0 at=0.5"], "--disturb: not with"),
        (["--step"], "--step: not with --remote (a remote run is paced by the robot"),
        (["--realtime"], "--realtime: not with --remote"),
        (["--dataset", "DIR"], "--dataset: not with --remote (the operator sees the robot in"),
        (
            ["--perturb", "5", "--dataset", "DIR"],
            "--perturb, --dataset: not with --remote (the robot's world is perturbed and "
            "disturbed at 'dial serve'; the operator sees the robot in decimated telemetry",
        ),
        (["--record", "x.rrd", "--no-predict"], "--record and --rerun draw the prediction"),
        (["--record", "x.txt"], ".rrd"),
        (["--lead", "2"], "--lead: only with --split block"),
        (["--split", "block", "--lead", "0"], "--lead must be above 0 s"),
        (["--diverge", "-1"], "--diverge must be above 0 mm"),
        (["--link", "delay=soon"], "delay"),
    ],
)
def test_what_a_remote_run_does_not_take_is_a_usage_error(
    extra: list[str], said: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["run", "pour.dial", "--remote", NOWHERE, *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dial: ") and err.count("\n") == 1, err
    assert said in err


@pytest.mark.parametrize("flag", [["--token-file", "t"], ["--link", "delay=1s"], ["--lead", "1"]])
def test_remote_options_need_remote(flag: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "pour.dial", *flag]) == 2
    assert f"{flag[0]} needs --remote URL" in capsys.readouterr().err


DOC = (Path(__file__).resolve().parents[2] / "docs" / "remote.md").read_text(encoding="utf-8")


def test_the_protocol_doc_names_every_message_error_and_refusal() -> None:
    """docs/remote.md is what a client of another library follows (test_safety.py's
    websockets client): every message type each way, every error and refusal code."""
    from dial.remote.protocol import ERRORS, TO_OPERATOR, TO_ROBOT, VERSION

    assert f"version {VERSION}" in DOC
    to_robot = DOC.split("### To the robot")[1].split("### To the operator")[0]
    to_operator = DOC.split("### To the operator")[1].split("### Errors")[0]
    for types, text in ((TO_ROBOT, to_robot), (TO_OPERATOR, to_operator)):
        for name, fields in types.items():
            row = next((r for r in text.splitlines() if r.startswith(f"| `{name}` |")), None)
            assert row is not None, name
            for field_name in fields:
                assert f"`{field_name.rstrip('?')}`" in row, (name, field_name)
    for code in (*ERRORS, "rejected", "late", "dropped", "mismatch"):
        assert f"`{code}`" in DOC, code


def test_the_benchmark_table_is_in_the_doc() -> None:
    """Pour and the light bulb, both splits, delays 0, 0.5, 2 and 7 s, with the ratio to
    the local run and the bytes each way (benchmarks/bench_remote.py's columns)."""
    rows = {tuple(c.strip() for c in r.strip("|").split("|")) for r in DOC.splitlines()}
    for script in ("pour", "light bulb"):
        for split in ("script", "block"):
            for delay in ("0 s", "0.5 s", "2 s", "7 s"):
                row = next((r for r in rows if r[:3] == (script, split, delay)), None)
                assert row is not None and len(row) == 8, (script, split, delay)
                assert row[4].endswith("x") and row[6].isdigit() and row[7].isdigit(), row
