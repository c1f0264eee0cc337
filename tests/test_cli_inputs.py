"""Hostile input on the command line (issue 15): one clear line and a documented exit
status for every case, never a traceback."""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from dial.cli import main

from .conftest import NEEDS_PLOT, NEEDS_VIDEO

DIAL = [sys.executable, "-m", "dial.cli"]

# (arguments, exit status, how the first line of stderr starts)
RUN_CASES = [
    (["--tick", "nan"], 2, "dial: --tick must be above 0 s and at most 60 s (as @tick), got nan"),
    (["--tick", "inf"], 2, "dial: --tick must be above 0 s and at most 60 s (as @tick), got inf"),
    (["--tick", "1e9"], 2, "dial: --tick must be above 0 s and at most 60 s (as @tick), got 1e+09"),
    (["--tick", "0"], 2, "dial: --tick must be above 0 s and at most 60 s (as @tick), got 0"),
    (["--speed", "-1"], 2, "dial: --speed must be a positive number, got -1"),
    (
        ["--speed", "1e-300"],
        2,
        "dial: the tick must be above 0 s and at most 60 s, got 1e+299 s (--speed 1e-300)",
    ),
    (["--seed", "-1", "--perturb", "5"], 2, "dial: --seed must be 0 or more, got -1"),
    (["--perturb", "-5"], 2, "dial: --perturb must be 0 mm or more, got -5"),
    (["--perturb", "nan"], 2, "dial: --perturb must be 0 mm or more, got nan"),
    (["--log", "/nonexistent/x.jsonl"], 1, "dial: cannot write the log: no such directory"),
    (["--log", "/tmp"], 1, "dial: cannot write the log: '/tmp' is a directory"),
    (["--log", "/dev/full"], 1, "dial: cannot write the log: No space left on device"),
    (["--log", "/proc/x.jsonl"], 1, "dial: cannot write the log: No such file or directory"),
    pytest.param(
        ["--video", "/proc/x.mp4"],
        1,
        "dial: cannot write the video: No such file or directory",
        marks=NEEDS_VIDEO,  # without the extra, that is said first
    ),
    (["--record", "/proc/x.rrd"], 1, "dial: cannot write the recording: No such file"),
    (["--record", "x.mp4"], 2, "dial: --record writes a .rrd file, not 'x.mp4'"),
    (["--video", "x.avi"], 2, "dial: --video writes .mp4 or .gif files"),
    (["--scene", "kitchen"], 2, "dial: --scene: 'kitchen' is neither a file nor a bundled scene"),
]


@pytest.mark.parametrize(("argv", "status", "first"), RUN_CASES)
def test_dial_run_options(argv: list[str], status: int, first: str) -> None:
    done = subprocess.run(
        [*DIAL, "run", "reactions.dial", "--quiet", *argv], capture_output=True, text=True
    )
    assert done.returncode == status, done.stderr
    assert done.stderr.splitlines()[0].startswith(first), done.stderr
    assert "Traceback" not in done.stderr


@pytest.fixture
def logs(tmp_path: Path) -> Path:
    (tmp_path / "binary.jsonl").write_bytes(Path(sys.executable).read_bytes()[:400])
    (tmp_path / "scene_only.jsonl").write_text('{"kind":"scene"}\n')
    (tmp_path / "typed.jsonl").write_text(
        '{"kind":"scene","scene":"x"}\n{"kind":"start","event":"a","line":"3","tick":1,"t":0}\n'
    )
    (tmp_path / "not_kind.jsonl").write_text('{"kind":"scene","scene":"x"}\n[1, 2]\n"x"\n')
    return tmp_path


@pytest.mark.parametrize(
    ("name", "first"),
    [
        ("binary", "binary.jsonl: not a dial run log (not UTF-8 text)"),
        ("scene_only", "scene_only.jsonl:1: this 'scene' record needs 'scene' as a string"),
        ("typed", "typed.jsonl:2: this 'start' record needs 'line' as an integer, got \"3\""),
        ("not_kind", "not_kind.jsonl:2: not a dial log record (no 'kind')"),
    ],
)
@pytest.mark.parametrize("extra", [[], ["--record", "out.rrd"]])
def test_dial_replay_of_bad_logs(
    logs: Path, name: str, first: str, extra: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    args = [a if a != "out.rrd" else str(logs / a) for a in extra]
    assert main(["replay", str(logs / f"{name}.jsonl"), *args]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"dial: {logs / first}") and err.count("\n") == 1


def test_fmt_of_a_latin1_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "latin.dial"
    path.write_bytes("// caf\xe9 au lait\n".encode("latin-1"))
    assert main(["fmt", str(path)]) == 1
    assert capsys.readouterr().err == (
        f"dial: {path}:1: not UTF-8 text (byte 7); dial scripts are UTF-8\n"
    )


def test_fmt_of_a_file_it_cannot_rewrite(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "x.dial"
    path.write_text("% a  get_joints\na #\n")
    monkeypatch.setattr(os, "access", lambda *args: False)  # as a read-only file (root or not)
    assert main(["fmt", str(path)]) == 1
    assert capsys.readouterr().err == f"dial: cannot rewrite {path}: Permission denied\n"
    assert path.read_text() == "% a  get_joints\na #\n" and os.listdir(tmp_path) == ["x.dial"]


def test_fmt_on_a_full_disk_keeps_the_script_whole(tmp_path: Path) -> None:
    """A file-size limit stands in for a full disk: the rewrite fails part-way through."""
    path = tmp_path / "x.dial"
    original = "% a  get_joints\n" + "a #\n" * 2000  # 8 kB, to be re-aligned
    path.write_text(original)

    def limit() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails (EFBIG)
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))

    done = subprocess.run(
        [*DIAL, "fmt", str(path)], capture_output=True, text=True, preexec_fn=limit
    )
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert done.stderr == f"dial: cannot rewrite {path}: File too large\n"
    assert path.read_text() == original and os.listdir(tmp_path) == ["x.dial"]


def test_an_observer_that_fails_mid_run_stops_it_cleanly(tmp_path: Path) -> None:
    import dial

    class Broken:
        what = "the broken observer"

        def begin(self, run: object) -> None:
            pass

        def period(self, periods: int, tick: int) -> None:
            if periods == 30:
                raise OSError(28, "No space left on device")

        def end(self, result: object) -> None:
            pass

    log = tmp_path / "log.jsonl"
    result = dial.run("reactions.dial", observers=[Broken()], log=log)
    assert not result.ok and result.error is not None
    assert result.error.startswith("the broken observer failed: [Errno 28] No space left")
    assert [r["kind"] for r in result.log.records[-2:]] == ["error", "summary"]


def test_check_of_a_latin1_script(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "latin.dial"
    path.write_bytes("// ok\n// caf\xe9\n".encode("latin-1"))
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out
    assert out.startswith(f"{path}:2:7: not UTF-8 text (byte 0xE9); dial scripts are UTF-8\n")


def test_world_of_a_latin1_world_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "w.toml"
    path.write_bytes('extends = "surface"\n# caf\xe9\n'.encode("latin-1"))
    assert main(["world", str(path)]) == 1
    assert capsys.readouterr().err == f"dial: {path}: not UTF-8 text (byte 25); TOML is UTF-8\n"


@NEEDS_PLOT  # without the extra, that is said first
def test_teach_snapshot_into_a_folder_it_cannot_make(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")  # a file where the folder's parent should be
    assert main(["teach", "--scene", "surface", "--snapshot", str(blocker / "shots")]) == 1
    err = capsys.readouterr().err
    assert err == f"dial: --snapshot: cannot make the folder {blocker / 'shots'}: Not a directory\n"
