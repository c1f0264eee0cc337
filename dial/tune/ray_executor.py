"""Trials as Ray tasks: a sweep on a Ray cluster, or on a local Ray started for it.

:class:`RayExecutor` is the :class:`~dial.tune.executor.Executor` of
``dial tune --executor ray``. Each item is one Ray task; Ray schedules the tasks on
the cluster's CPUs, re-runs a task whose worker process died (``RETRIES`` times),
and the results come back in item order. Only the function (a reference to a
module-level function), the items and the results cross the wire: every worker
imports ``dial`` and builds its own simulation, so it needs ``dial`` installed and
the script and scene files at the same paths.

Ray is the optional extra ``dial[ray]`` and is imported only here, when an
executor is made. Connecting to a cluster is bounded in time: Ray's own client
retries a wrong address for minutes.
"""

from __future__ import annotations

import logging
import os
import socket
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager, redirect_stdout
from types import ModuleType, TracebackType
from typing import Any, TypeVar, cast

from dial.errors import DialError
from dial.tune.executor import WORKER_DIED, Each, Initializer, ItemsDone

T = TypeVar("T")
R = TypeVar("R")

INSTALL = "pip install 'dial[ray]'"
RETRIES = 2  # re-runs of a task whose worker died, before it counts as lost
CONNECT_TIMEOUT_S = 20.0  # to reach a cluster and register with it
PROBE_TIMEOUT_S = 5.0  # to open a TCP connection to its address
WAIT_S = 0.2  # the longest a Ctrl-C waits to be seen while results are awaited
LOCAL_OBJECT_STORE = 100 * 2**20  # bytes: a local Ray only ever holds trials and results
ADDRESS_FORM = "HOST:PORT (e.g. 10.0.0.5:6379), ray://HOST:PORT or auto"
AUTH_HINT = (
    "the cluster wants its authentication token: set RAY_AUTH_MODE=token and the token "
    "(RAY_AUTH_TOKEN, or ~/.ray/auth_token), see docs/tuning.md"
)


class RayUsageError(DialError):
    """Ray is not installed, or the address is not an address: a usage error."""


class RayConnectError(DialError):
    """No Ray cluster could be reached at the address, in time."""


def import_ray() -> ModuleType:
    """The ``ray`` module, or a :class:`RayUsageError` that names the install command."""
    try:
        import ray
    except ImportError as e:
        raise RayUsageError(f"--executor ray needs Ray: {INSTALL} ({e})") from None
    return ray


def split_address(address: str) -> tuple[str, int]:
    """``HOST:PORT`` or ``ray://HOST:PORT`` as (host, port); RayUsageError if malformed."""
    host, colon, port = address.removeprefix("ray://").rpartition(":")
    host = host.strip("[]")  # an IPv6 host is written [::1]:6379
    if not (colon and host and port.isdigit() and 0 < int(port) < 65536):
        raise RayUsageError(f"--address: expected {ADDRESS_FORM}, got '{address}'")
    return host, int(port)


def _run_task(fn: Callable[[T], R], item: T, initializer: Initializer | None) -> R:
    """The body of every Ray task, in a worker process."""
    if initializer is not None:
        initializer()  # idempotent: a worker runs many tasks
    return fn(item)


class RayExecutor:
    """Run each item as a Ray task.

    ``address`` is a cluster's ``HOST:PORT``, ``ray://HOST:PORT`` (Ray Client) or
    ``auto`` (the cluster this machine belongs to); without it, ``RAY_ADDRESS``
    if set, else a local Ray with ``cpus`` CPUs (default: all cores) is started
    for the map and shut down after it. If this process is already connected to
    Ray (a notebook, the tests), that session is used. Use it as a context
    manager to keep one connection over several maps.
    """

    def __init__(
        self,
        address: str | None = None,
        cpus: int | None = None,
        initializer: Initializer | None = None,
    ) -> None:
        self.ray = import_ray()
        env = os.environ.get("RAY_ADDRESS") or None
        self.address = env if address in (None, "auto") and env else address
        if self.address not in (None, "auto"):
            split_address(self.address)
        if cpus is not None and self.address is not None:
            raise RayUsageError(
                "--jobs sets the CPUs of a local Ray; on a cluster, its nodes' CPUs decide"
            )
        self.cpus = cpus or os.cpu_count() or 1
        self.initializer = initializer
        self.where = ""  # how the last map ran, for the summary line: set on connecting
        self._opened = False

    def __enter__(self) -> RayExecutor:
        self.connect()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()

    def connect(self) -> None:
        """Start a local Ray or connect to the cluster, unless this process already is."""
        ray = self.ray
        if self._opened:
            return
        if ray.is_initialized():
            self.where = f"on this process's Ray session ({self._cpus()} CPUs)"
            return
        if self.address is None:
            try:
                ray.init(
                    address="local",
                    num_cpus=self.cpus,
                    include_dashboard=False,
                    object_store_memory=LOCAL_OBJECT_STORE,
                    logging_level=logging.ERROR,
                )
            except Exception as e:  # a port taken, no room for its files, ...
                raise RayConnectError(f"cannot start a local Ray: {_first_line(str(e))}") from e
            self.where = f"on a local Ray with {self.cpus} CPUs"
        else:
            _connect(ray, self.address)
            at = self.address
            if at == "auto":
                at = ray.get_runtime_context().gcs_address
            self.where = f"on the Ray cluster at {at} ({self._cpus()} CPUs)"
        self._opened = True

    def close(self) -> None:
        """Shut down the local Ray, or disconnect from the cluster, if :meth:`connect` did."""
        if self._opened:
            self.ray.shutdown()
            self._opened = False

    def _cpus(self) -> int:
        return int(self.ray.cluster_resources().get("CPU", 0))

    def map(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        progress: ItemsDone | None = None,
        each: Each[R] | None = None,
    ) -> list[R]:
        # Ray prints its workers' output and its own notes (a worker died, a task is
        # retried) on this process's stdout, which carries the table: send them to stderr.
        with redirect_stdout(sys.stderr):
            opened = not self._opened
            self.connect()
            try:
                return self._map(fn, items, lost, progress, each)
            finally:
                if opened:
                    self.close()

    def _map(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        progress: ItemsDone | None,
        each: Each[R] | None,
    ) -> list[R]:
        ray = self.ray
        task = ray.remote(max_retries=RETRIES, retry_exceptions=False)(_run_task)
        index = {task.remote(fn, item, self.initializer): i for i, item in enumerate(items)}
        results: dict[int, R] = {}
        pending = list(index)
        try:
            while pending:
                # Waiting with no timeout would hold off Ctrl-C until a result arrives.
                done, pending = ray.wait(pending, num_returns=1, timeout=WAIT_S)
                for ref in done:  # let go of the reference: Ray may free the object
                    i = index.pop(ref)
                    result = self._result(ref, items[i], lost)
                    results[i] = result if each is None else each(i, result)
                    if progress is not None:
                        progress(len(results))
        except BaseException:  # an interrupt: the remaining tasks must not run on
            for ref in pending:
                ray.cancel(ref, force=True)
            raise
        return [results[i] for i in range(len(items))]

    def _result(self, ref: Any, item: T, lost: Callable[[T, str], R]) -> R:
        errors = self.ray.exceptions
        try:
            return cast(R, self.ray.get(ref))
        except errors.WorkerCrashedError:  # it killed its worker 1 + RETRIES times
            return lost(item, WORKER_DIED)
        except errors.RayTaskError as e:  # fn raised, as ProcessExecutor reports it
            cause = e.cause if isinstance(e.cause, BaseException) else e
            return lost(item, f"{type(cause).__name__}: {cause}")
        except errors.RayError as e:  # its node died, its result was lost, ...
            return lost(item, f"{type(e).__name__}: {_first_line(str(e))}")


def _first_line(text: str) -> str:
    return text.strip().splitlines()[0] if text.strip() else ""


def _connect(ray: ModuleType, address: str) -> None:
    """``ray.init(address)`` within CONNECT_TIMEOUT_S, or one RayConnectError line."""
    if address != "auto":
        _probe(address)
    failure: list[BaseException] = []

    def attempt() -> None:
        try:
            ray.init(address=address, include_dashboard=False, logging_level=logging.ERROR)
        except BaseException as e:
            failure.append(e)

    # Ray's client retries an address that does not answer as a cluster for minutes,
    # logging every retry from its native code on file descriptor 2: wait in a thread,
    # with those logs set aside (they name the cause when it is a missing token).
    with _captured_fd2() as captured:
        thread = threading.Thread(target=attempt, name="dial-ray-connect", daemon=True)
        thread.start()
        thread.join(CONNECT_TIMEOUT_S)
        text = captured() + "".join(str(e) for e in failure)
    if "InvalidAuthToken" in text:
        raise RayConnectError(f"cannot connect to Ray at {address}: {AUTH_HINT}")
    if thread.is_alive():
        raise RayConnectError(
            f"no Ray cluster answered at {address} within {CONNECT_TIMEOUT_S:g} s"
        )
    if failure:
        raise RayConnectError(f"cannot connect to Ray at {address}: {_first_line(text)}")


def _probe(address: str) -> None:
    """Fail at once if nothing listens at the address, rather than after Ray's retries."""
    host, port = split_address(address)
    try:
        with socket.create_connection((host, port), PROBE_TIMEOUT_S):
            pass
    except socket.gaierror:
        raise RayConnectError(f"cannot connect to Ray at {address}: unknown host") from None
    except OSError as e:
        why = "no answer" if isinstance(e, TimeoutError) else (e.strerror or str(e)).lower()
        raise RayConnectError(f"cannot connect to Ray at {address}: {why}") from None


@contextmanager
def _captured_fd2() -> Iterator[Callable[[], str]]:
    """Send what is written on file descriptor 2 to a file; yield a reader of it."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)

        def read() -> str:
            sink.seek(0)
            return sink.read().decode(errors="replace")

        try:
            yield read
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
