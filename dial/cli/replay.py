"""``dial replay``: a run's timeline from its log; its recording or video rebuilt."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from dial.cli.common import UsageError


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "replay",
        help="print a run's timeline from its log, or rebuild its recording or video",
        description="Print the timeline of a run from its --log: each event's start and end "
        "with tick, simulated time and outcome, contacts, conditions, messages and the "
        "criteria. With --record or --video, also rebuild a rerun recording or a video from "
        "the log's states (written by 'dial run --log FILE --log-states').",
    )
    p.add_argument("log", metavar="LOG.jsonl", help="a log written by 'dial run --log'")
    p.add_argument("--record", metavar="FILE.rrd", help="rebuild a rerun recording")
    p.add_argument(
        "--video",
        metavar="FILE.mp4",
        help="render the states to an .mp4 or .gif, one frame per state, from the camera of "
        "'dial run --video' (needs the 'video' extra)",
    )
    p.set_defaults(func=cmd_replay)


def cmd_replay(args: argparse.Namespace) -> int:
    from dial.api import writable
    from dial.recording.timeline import read_log, timeline

    path = Path(args.log)
    if args.record and Path(args.record).suffix.lower() != ".rrd":
        raise UsageError(f"--record writes a .rrd file, not '{args.record}'")
    if args.video:
        if sys.platform.startswith("linux"):  # offscreen on the CPU; before MuJoCo loads
            import os

            os.environ.setdefault("MUJOCO_GL", "egl")
        from dial.recording.video import video_problem

        problem = video_problem(args.video)
        if problem is not None:
            raise UsageError(problem)
        writable(args.video, "the video")
    if args.record:
        writable(args.record, "the recording")
    records = read_log(path)
    if args.record:
        from dial.recording.replay import rebuild

        frames = rebuild(records, Path(args.record), f"{path.name} (replay)", path.parent)
        print(f"{args.record}: {frames} frames rebuilt from {path}", file=sys.stderr)
    if args.video:
        from dial.recording.replay import render_video

        frames = render_video(records, Path(args.video), path.parent)
        print(f"{args.video}: {frames} frames rendered from {path}", file=sys.stderr)
    sys.stdout.write(timeline(records))
    return 0
