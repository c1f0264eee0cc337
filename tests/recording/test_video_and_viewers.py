"""--video renders the run; --rerun and --viewer fail cleanly where there is no display."""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dial.cli import main
from dial.recording.video import HEIGHT, VIDEO_FPS, WIDTH, video_problem

DIAL = [sys.executable, "-m", "dial.cli"]
linux_only = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="DISPLAY is X11's")


def _headless() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    return env | {"MUJOCO_GL": "egl"}


def test_video_is_rendered_at_a_steady_rate_of_simulated_time(
    short_script: Path, tmp_path: Path
) -> None:
    pytest.importorskip("imageio_ffmpeg", reason="the 'video' extra is not installed")
    import imageio.v2 as imageio

    video, log = tmp_path / "run.mp4", tmp_path / "run.jsonl"
    cmd = [*DIAL, "run", str(short_script), "--video", str(video), "--log", str(log), "--json"]
    cmd.append("--log-states")
    done = subprocess.run(cmd, capture_output=True, text=True, env=_headless(), timeout=120)
    assert done.returncode in (0, 1), done.stderr  # 1: the surface criteria want a fit
    sim_time = json.loads(done.stdout.splitlines()[-1])["sim_time"]
    reader = imageio.get_reader(video)
    assert reader.get_meta_data()["fps"] == VIDEO_FPS
    frames = [np.asarray(f) for f in reader.iter_data()]
    assert len(frames) == round(sim_time / 0.01) // round(100 / VIDEO_FPS) + 1
    assert frames[0].shape == (HEIGHT, WIDTH, 3)
    assert np.abs(frames[-1].astype(int) - frames[0].astype(int)).mean() > 1  # the arm moved

    # dial replay --video renders the logged states (25 Hz, as the video) to the same film.
    again = tmp_path / "replay.mp4"
    cmd = [*DIAL, "replay", str(log), "--video", str(again)]
    done = subprocess.run(cmd, capture_output=True, text=True, env=_headless(), timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr.endswith(f"{again}: {len(frames)} frames rendered from {log}\n")
    replayed = imageio.get_reader(again)
    assert replayed.get_meta_data()["fps"] == VIDEO_FPS
    shown = [np.asarray(f).astype(int) for f in replayed.iter_data()]
    live = [f.astype(int) for f in frames]
    same = [np.abs(a - b).mean() for a, b in zip(live, shown, strict=True)]
    late = [np.abs(a - b).mean() for a, b in zip(live[1:], shown, strict=False)]
    # The states hold positions to 0.1 mm, and both films are compressed: each picture
    # differs by a few grey levels at most, and less than it does from the next frame.
    assert max(same) < 2.0
    assert np.mean(same) < np.mean(late)


def test_video_needs_a_known_format_and_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    assert video_problem("run.avi") == "--video writes .mp4 or .gif files, not '.avi'"
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name: None if "imageio" in name else real(name)
    )
    problem = video_problem("run.mp4")
    assert problem is not None and "pip install 'dial[video]'" in problem


def test_video_without_the_extra_is_a_usage_error(
    short_script: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("MUJOCO_GL", "egl")
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name: None if "imageio" in name else real(name)
    )
    assert main(["run", str(short_script), "--video", "x.gif"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'video' extra" in err


@linux_only
@pytest.mark.parametrize("flag", ["--rerun", "--viewer"])
def test_no_display_ends_with_exit_1_and_one_line(
    flag: str,
    short_script: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["run", str(short_script), flag]) == 1
    captured = capsys.readouterr()
    assert captured.err == (
        f"dial: {flag} needs a display, and neither DISPLAY nor WAYLAND_DISPLAY is set; "
        "use --record FILE.rrd or --video FILE.mp4 instead\n"
    )


@linux_only
def test_no_display_from_the_shell_is_not_a_traceback(short_script: Path) -> None:
    cmd = [*DIAL, "run", str(short_script), "--viewer"]
    done = subprocess.run(cmd, capture_output=True, text=True, env=_headless(), timeout=60)
    assert done.returncode == 1
    assert done.stderr.count("\n") == 1 and "needs a display" in done.stderr
