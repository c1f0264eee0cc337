"""Task time through a delayed link, as a ratio to the local run, and the bytes each way.

For pour and the light bulb, at one-way delays of 0, 0.5, 2 and 7 s, with ``--split
script`` and ``--split block``: a real ``dial serve`` on 127.0.0.1 (a free port) and
``dial run --remote --link``. To keep it affordable the robot runs ``--pace P`` (P wall
seconds per simulated second) and the link's delay is scaled by the same P: the whole
remote run then happens P times faster than it would in real time, and its task time in
real time is the robot's wall time from its first tick to its last, / P, plus the delay
each way (the command's and the last report's). The local run's task time is its
simulated time (a real robot runs in real time). ``end to end`` adds what the operator
waits for besides: connecting, the round trip it measures, the robot's check of the script
and its scene's set-up. Each server process is stopped at the end.

    python benchmarks/bench_remote.py [--pace 0.25] [--delays 0,0.5,2,7] [--scripts pour,lightbulb]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _dial(*args: str) -> list[str]:
    return [sys.executable, "-m", "dial.cli", *args]


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _json(argv: list[str]) -> dict[str, object]:
    out = subprocess.run(argv, capture_output=True, text=True, env=_env(), timeout=900)
    last = out.stdout.strip().splitlines()[-1] if out.stdout.strip() else "{}"
    return dict(json.loads(last)) if last.startswith("{") else {"ok": False, "error": out.stderr}


def bench(script: str, pace: float, delays: list[float], folder: Path) -> list[str]:
    local = _json(_dial("run", script, "--quiet", "--json"))
    task = float(str(local["sim_time"]))
    rows = [f"{script:<16} local {task:7.2f} s (simulated time)"]
    print(rows[0], flush=True)
    server = subprocess.Popen(
        _dial(
            "serve",
            "--listen",
            "127.0.0.1:0",
            "--pace",
            str(pace),
            "--token-file",
            str(folder / f"{script}.token"),
        ),
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env=_env(),
        start_new_session=True,
    )
    try:
        assert server.stdout is not None
        url = re.search(r"ws://\S+", server.stdout.readline())
        assert url is not None, "dial serve did not start"
        for split in ("script", "block"):
            for delay in delays:
                link = f"delay={delay * pace:g}s seed=1"
                r = _json(
                    _dial(
                        "run",
                        script,
                        "--remote",
                        url.group(0),
                        "--token-file",
                        str(folder / f"{script}.token"),
                        "--split",
                        split,
                        "--link",
                        link,
                        "--no-predict",
                        "--quiet",
                        "--json",
                    )
                )
                remote = r.get("remote") if isinstance(r.get("remote"), dict) else {}
                assert isinstance(remote, dict)
                time = float(str(r.get("robot_wall_time", "nan"))) / pace + 2 * delay
                whole = float(str(r.get("wall_time", "nan"))) / pace
                up, down = remote.get("sent_bytes", 0), remote.get("received_bytes", 0)
                rows.append(
                    f"{script:<16} {split:<6} {delay:4g} s  {time:8.2f} s  {time / task:6.2f}x  "
                    f"{whole:8.2f} s  {up:>8} B  {down:>9} B  {'ok' if r.get('ok') else 'FAILED'}"
                )
                print(rows[-1], flush=True)
    finally:
        os.killpg(server.pid, signal.SIGKILL)
        server.wait()
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--pace", type=float, default=0.25)
    p.add_argument("--delays", default="0,0.5,2,7")
    p.add_argument("--scripts", default="pour,lightbulb")
    args = p.parse_args()
    delays = [float(d) for d in args.delays.split(",")]
    commit = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    print(f"commit {commit or '?'}; load average {_load()} (1, 5, 15 min)")
    print(f"pace {args.pace:g}: link delays scaled by it, times divided by it")
    print("script           split  delay  task time  / local   end to end  bytes up  bytes down")
    with tempfile.TemporaryDirectory() as folder:
        for script in args.scripts.split(","):
            bench(f"{script}.dial", args.pace, delays, Path(folder))
    print(f"load average at the end {_load()}: a loaded machine inflates every ratio")


def _load() -> str:
    return ", ".join(f"{x:.1f}" for x in os.getloadavg())


if __name__ == "__main__":
    main()
