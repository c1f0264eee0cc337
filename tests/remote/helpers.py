"""Real ``dial serve`` and ``dial run --remote`` processes on 127.0.0.1, free ports only.

Every process starts in its own process group and is killed with it in a finally-block,
so that no test leaves one behind.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LINK_KINDS = {
    "session",
    "received",
    "sent",
    "acknowledged",
    "reported",
    "late",
    "lost",
    "diverged",
    "connected",
    "rtt",
    "lead",
    "refused",
    "error",
}


def env() -> dict[str, str]:
    e = dict(os.environ)
    e["PYTHONPATH"] = str(ROOT) + os.pathsep + e.get("PYTHONPATH", "")
    return e


def dial(*args: str) -> list[str]:
    return [sys.executable, "-m", "dial.cli", *args]


class Server:
    """A running ``dial serve``: its URL, token file and log."""

    def __init__(self, proc: subprocess.Popen[str], url: str, folder: Path) -> None:
        self.proc, self.url, self.folder = proc, url, folder
        self.token_file = folder / "token"
        self.log = folder / "robot.jsonl"

    def records(self) -> list[dict[str, object]]:
        text = self.log.read_text(encoding="utf-8") if self.log.exists() else ""
        return [json.loads(line) for line in text.splitlines() if line.strip()]


def _kill(proc: subprocess.Popen[str]) -> None:
    if proc.poll() is None:
        with suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
    with suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=10)


@contextmanager
def server(folder: Path, *args: str, pace: float = 0.1) -> Iterator[Server]:
    """``dial serve`` on a free loopback port, killed (with its group) at the end."""
    folder.mkdir(parents=True, exist_ok=True)
    argv = dial(
        "serve",
        "--listen",
        "127.0.0.1:0",
        "--token-file",
        str(folder / "token"),
        "--log",
        str(folder / "robot.jsonl"),
        "--pace",
        str(pace),
        *args,
    )
    proc = subprocess.Popen(
        argv,
        stdout=subprocess.PIPE,
        stderr=open(folder / "serve.err", "w"),  # noqa: SIM115
        text=True,
        env=env(),
        start_new_session=True,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        m = re.search(r"(ws://127\.0\.0\.1:\d+)", line)
        assert m, f"dial serve printed {line!r}; {(folder / 'serve.err').read_text()}"
        yield Server(proc, m.group(1), folder)
    finally:
        _kill(proc)


@contextmanager
def operator(
    srv: Server, script: str, *args: str, log: Path | None = None
) -> Iterator[subprocess.Popen[str]]:
    """``dial run SCRIPT --remote`` started (not waited for), killed at the end."""
    argv = dial(
        "run", script, "--remote", srv.url, "--token-file", str(srv.token_file), "--json", *args
    )
    if log is not None:
        argv += ["--log", str(log)]
    proc = subprocess.Popen(
        argv,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env(),
        start_new_session=True,
    )
    try:
        yield proc
    finally:
        _kill(proc)


def run_operator(
    srv: Server, script: str, *args: str, log: Path | None = None, timeout: float = 120
) -> tuple[int, dict[str, object] | None, str]:
    """Run an operator to its end: (exit status, its --json object, its stderr)."""
    with operator(srv, script, *args, log=log) as proc:
        out, err = proc.communicate(timeout=timeout)
    last = out.strip().splitlines()[-1] if out.strip() else ""
    return proc.returncode, json.loads(last) if last.startswith("{") else None, err


def robot_log(records: list[dict[str, object]], session: int = 1) -> list[dict[str, object]]:
    """One session's records without link records and wall times."""
    out, current = [], 0
    for r in records:
        if r["kind"] == "session":
            current = int(str(r["session"]))
        if current != session or r["kind"] in LINK_KINDS:
            continue
        out.append({k: v for k, v in r.items() if k not in ("wall_time", "wall")})
    return out


def wait_for(predicate: object, timeout: float, step: float = 0.05) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():  # type: ignore[operator]
            return True
        time.sleep(step)
    return False
