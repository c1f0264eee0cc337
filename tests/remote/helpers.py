"""Real ``dial serve``, ``dial link`` and ``dial run --remote`` processes on 127.0.0.1, free
ports only.

No test leaves a process behind: every process starts in a process group of its own and
is registered here; a test kills what it started when it is done with it, and
:func:`kill_all` (run by tests/remote/conftest.py's session finalizer, at exit, and on
SIGTERM, as a timed-out run gets) kills every group still alive. On Linux a child also
gets SIGKILL when the test process dies, whatever kills it (``PR_SET_PDEATHSIG``, set by a
small launcher before it becomes ``dial``). Every wait on a process has a timeout.
"""

from __future__ import annotations

import atexit
import json
import os
import re
import select
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import IO

from dial.remote.session import LINK_RECORDS

ROOT = Path(__file__).resolve().parents[2]
START_S = 90.0  # a process must say where it listens within this (a loaded machine)
WAIT_S = 150.0  # no operator in these tests runs longer
# Sets PR_SET_PDEATHSIG (SIGKILL) and becomes the command: it dies with the test process.
_LAUNCH = (
    "import ctypes, os, sys; ctypes.CDLL(None, use_errno=True).prctl(1, 9, 0, 0, 0); "
    "os.execv(sys.executable, [sys.executable, *sys.argv[1:]])"
)
_started: list[subprocess.Popen[str]] = []
_lock = threading.Lock()


def env() -> dict[str, str]:
    e = dict(os.environ)
    e["PYTHONPATH"] = str(ROOT) + os.pathsep + e.get("PYTHONPATH", "")
    return e


def dial(*args: str) -> list[str]:
    return [sys.executable, "-m", "dial.cli", *args]


def spawn(
    argv: list[str],
    stdout: int | IO[str] | None,
    stderr: int | IO[str] | None,
    extra_env: dict[str, str] | None = None,
) -> subprocess.Popen[str]:
    """Start ``argv`` (a ``dial(...)`` command line) in a process group of its own,
    registered for :func:`kill_all`."""
    if sys.platform.startswith("linux") and argv[0] == sys.executable:
        argv = [sys.executable, "-c", _LAUNCH, *argv[1:]]
    with _lock:
        proc = subprocess.Popen(
            argv,
            stdout=stdout,
            stderr=stderr,
            text=True,
            env={**env(), **(extra_env or {})},
            start_new_session=True,
        )
        _started.append(proc)
    return proc


def kill(proc: subprocess.Popen[str]) -> None:
    """Kill ``proc``'s process group, and reap it."""
    if proc.poll() is None:
        with suppress(ProcessLookupError, PermissionError):
            os.killpg(proc.pid, signal.SIGKILL)
    with suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=10)
    with _lock, suppress(ValueError):
        _started.remove(proc)


def started() -> list[subprocess.Popen[str]]:
    """The processes started and not killed yet."""
    with _lock:
        return list(_started)


def kill_all() -> None:
    """Kill every process group the tests started that is still alive."""
    with _lock:
        procs = list(_started)
    for proc in procs:
        kill(proc)


def _on_sigterm(signum: int, frame: object) -> None:
    kill_all()
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    os.kill(os.getpid(), signal.SIGTERM)


atexit.register(kill_all)
if threading.current_thread() is threading.main_thread() and signal.getsignal(signal.SIGTERM) in (
    signal.SIG_DFL,
    None,
):
    signal.signal(signal.SIGTERM, _on_sigterm)


def first_line(proc: subprocess.Popen[str], timeout: float = START_S) -> str:
    """The first line ``proc`` prints, within ``timeout`` (else ``''``)."""
    stream = proc.stdout
    assert stream is not None
    ready, _, _ = select.select([stream], [], [], timeout)
    return stream.readline() if ready else ""


class Server:
    """A running ``dial serve``: its URL, token file and log."""

    def __init__(self, proc: subprocess.Popen[str], url: str, folder: Path) -> None:
        self.proc, self.url, self.folder = proc, url, folder
        self.token_file = folder / "token"
        self.log = folder / "robot.jsonl"

    def records(self) -> list[dict[str, object]]:
        text = self.log.read_text(encoding="utf-8") if self.log.exists() else ""
        return [json.loads(line) for line in text.splitlines() if line.strip()]

    def sessions(self) -> list[int]:
        return [int(str(r["session"])) for r in self.records() if r["kind"] == "session"]

    def last_session(self) -> int:
        return max(self.sessions(), default=0)


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
    with open(folder / "serve.err", "w") as err:
        proc = spawn(argv, stdout=subprocess.PIPE, stderr=err)
    try:
        line = first_line(proc)
        m = re.search(r"(ws://127\.0\.0\.1:\d+)", line)
        assert m, f"dial serve printed {line!r}; {(folder / 'serve.err').read_text()}"
        yield Server(proc, m.group(1), folder)
    finally:
        kill(proc)


@contextmanager
def link(target: str, spec: str) -> Iterator[str]:
    """``dial link`` on a free loopback port to ``target``: its URL; killed at the end."""
    proc = spawn(
        dial("link", "--listen", "127.0.0.1:0", "--to", target, spec),
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )
    try:
        m = re.search(r"(ws://127\.0\.0\.1:\d+)", first_line(proc))
        assert m, "dial link did not say where it listens"
        yield m.group(1)
    finally:
        kill(proc)


@contextmanager
def operator(
    srv: Server, script: str, *args: str, log: Path | None = None, url: str | None = None
) -> Iterator[subprocess.Popen[str]]:
    """``dial run SCRIPT --remote`` started (not waited for), killed at the end."""
    argv = dial(
        "run",
        script,
        "--remote",
        url or srv.url,
        "--token-file",
        str(srv.token_file),
        "--json",
        *args,
    )
    if log is not None:
        argv += ["--log", str(log)]
    proc = spawn(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        yield proc
    finally:
        kill(proc)


def run_operator(
    srv: Server,
    script: str,
    *args: str,
    log: Path | None = None,
    url: str | None = None,
    timeout: float = WAIT_S,
) -> tuple[int, dict[str, object] | None, str]:
    """Run an operator to its end: (exit status, its --json object, its stderr)."""
    with operator(srv, script, *args, log=log, url=url) as proc:
        out, err = proc.communicate(timeout=timeout)
    last = out.strip().splitlines()[-1] if out.strip() else ""
    return proc.returncode, json.loads(last) if last.startswith("{") else None, err


def run_dial(*args: str, timeout: float = WAIT_S) -> subprocess.CompletedProcess[str]:
    """A ``dial`` command run to its end (registered, killed if it overruns)."""
    proc = spawn(dial(*args), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        out, err = proc.communicate(timeout=timeout)
    finally:
        kill(proc)
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


def read_log(path: Path) -> list[dict[str, object]]:
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def robot_log(records: list[dict[str, object]], session: int = 1) -> list[dict[str, object]]:
    """One session's records without link records and wall times."""
    out, current = [], 0
    for r in records:
        if r["kind"] == "session":
            current = int(str(r["session"]))
        if current != session or r["kind"] in LINK_RECORDS:
            continue
        out.append({k: v for k, v in r.items() if k not in ("wall_time", "wall")})
    return out


def wait_for(predicate: Callable[[], bool], timeout: float, step: float = 0.05) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(step)
    return False
