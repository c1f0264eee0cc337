"""``dial tune --executor ray`` usage: a missing extra, bad addresses, a bounded connect.

None of these starts Ray: an address is refused before it is handed to Ray, and the
connect timeout is tested on a stand-in for ``ray.init`` that never returns.
"""

from __future__ import annotations

import os
import socket
import sys
import threading
import time
from collections.abc import Iterator
from types import SimpleNamespace
from typing import Any

import pytest

from dial.cli import main
from dial.tune import ray_executor
from dial.tune.ray_executor import RayConnectError

from ..conftest import NEEDS_RAY

TUNE = ["tune", "lightbulb", "--ticks", "0.1:0.2:2"]


@pytest.fixture(autouse=True)
def no_ray_address(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RAY_ADDRESS", raising=False)


@pytest.fixture
def listener() -> Iterator[int]:
    """A port where something accepts connections and never says a word."""
    with socket.create_server(("127.0.0.1", 0)) as server:
        yield server.getsockname()[1]


def _free_port() -> int:
    with socket.create_server(("127.0.0.1", 0)) as server:
        return int(server.getsockname()[1])  # closed again: nothing listens there


def test_executor_ray_without_ray_installed_names_the_install_command(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray fails
    assert main([*TUNE, "--executor", "ray"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dial: --executor ray needs Ray: pip install 'dial[ray]'")
    assert err.count("\n") == 1


@NEEDS_RAY  # without Ray, that is said first
@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--address", "nonsense"], "dial: --address: expected HOST:PORT (e.g. 10.0.0.5:6379)"),
        (["--address", "head:99999"], "dial: --address: expected HOST:PORT"),
        (["--address", ":6379"], "dial: --address: expected HOST:PORT"),
        (["--address", "head:6379", "--jobs", "2"], "dial: --jobs sets the CPUs of a local Ray"),
    ],
)
def test_a_malformed_address_is_a_usage_error(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*TUNE, "--executor", "ray", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and err.count("\n") == 1


def test_address_without_executor_ray_is_a_usage_error(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main([*TUNE, "--address", "auto"]) == 2
    assert capsys.readouterr().err == "dial: --address needs --executor ray\n"


@NEEDS_RAY
def test_an_address_where_nothing_listens_is_one_line_at_once(
    capsys: pytest.CaptureFixture[str],
) -> None:
    address = f"127.0.0.1:{_free_port()}"
    start = time.monotonic()
    assert main([*TUNE, "--executor", "ray", "--address", address]) == 1
    assert time.monotonic() - start < ray_executor.CONNECT_TIMEOUT_S  # not Ray's retries
    err = capsys.readouterr().err
    assert err == f"dial: cannot connect to Ray at {address}: connection refused\n"


def _stand_in(init: Any) -> Any:
    return SimpleNamespace(init=init)


def test_connecting_gives_up_after_the_timeout(
    listener: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(ray_executor, "CONNECT_TIMEOUT_S", 0.3)
    release = threading.Event()
    address = f"127.0.0.1:{listener}"
    with pytest.raises(RayConnectError) as info:
        ray_executor._connect(_stand_in(lambda **_: release.wait()), address)
    release.set()
    assert str(info.value) == f"no Ray cluster answered at {address} within 0.3 s"


def test_a_missing_token_is_named_and_ray_logs_are_kept_off_the_terminal(
    listener: int, capfd: pytest.CaptureFixture[str]
) -> None:
    def init(**_: Any) -> None:  # as Ray's native client does, on file descriptor 2
        os.write(2, b"[W gcs_client.cc] RPC error: InvalidAuthToken: token is missing\n")
        raise ConnectionError("Failed to connect to Ray cluster")

    with pytest.raises(RayConnectError) as info:
        ray_executor._connect(_stand_in(init), f"127.0.0.1:{listener}")
    assert "the cluster wants its authentication token: set RAY_AUTH_MODE=token" in str(info.value)
    assert capfd.readouterr().err == ""
