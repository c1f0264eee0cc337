"""Whatever happens to a test, no ``dial serve``, ``dial link`` or operator outlives it
(tests/remote/helpers.py registers each process group it starts): a test's own
processes die with it, a module's shared server with the module, all with the session."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.remote.helpers import kill, kill_all, started


@pytest.fixture(scope="session", autouse=True)
def _none_left_by_the_session() -> Iterator[None]:
    yield
    kill_all()


@pytest.fixture(autouse=True)
def _none_left_by_a_test() -> Iterator[None]:
    before = set(started())  # a module's shared server is started before this
    yield
    for proc in started():
        if proc not in before:
            kill(proc)
