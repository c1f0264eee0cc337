"""A sweep's dataset on a local Ray (on 127.0.0.1, stopped after): the process pool's files."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pyarrow", reason="the dataset tests need the 'dataset' extra (pyarrow)")
ray = pytest.importorskip("ray", reason="needs the 'ray' extra")

from dial.tune import ProcessExecutor  # noqa: E402
from dial.tune.ray_executor import RayExecutor  # noqa: E402

from . import layout  # noqa: E402
from .helpers import digest, sweep  # noqa: E402


def test_a_sweep_on_ray_writes_the_process_pools_files(tmp_path: Path) -> None:
    pool = sweep(tmp_path / "pool", ProcessExecutor(2))
    ray.init(
        address="local",
        num_cpus=2,
        include_dashboard=False,
        _node_ip_address="127.0.0.1",
        object_store_memory=100 * 2**20,
    )
    try:
        on_ray = sweep(tmp_path / "ray", RayExecutor())  # this process's Ray session
    finally:
        ray.shutdown()
    assert not ray.is_initialized()
    assert on_ray == pool
    assert digest(tmp_path / "ray") == digest(tmp_path / "pool")
    assert layout.check(tmp_path / "ray")["info"]["total_episodes"] == 3
