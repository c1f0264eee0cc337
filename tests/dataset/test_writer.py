"""The dataset writer on episodes made without physics: layout, appending, rollover, stats,
and bad input that leaves the folder as it was."""

from __future__ import annotations

import errno
import json
from pathlib import Path

import numpy as np
import pytest

from dial.errors import OptionError

pytest.importorskip("pyarrow", reason="the dataset tests need the 'dataset' extra (pyarrow)")

from dial.dataset import files, tables
from dial.dataset.writer import DatasetError, DatasetWriter

from . import layout
from .helpers import digest, fake_episode


def test_episodes_written_and_appended_make_one_consistent_dataset(tmp_path: Path) -> None:
    root = tmp_path / "new" / "ds"  # its parents are made too
    with DatasetWriter(root) as writer:
        assert [writer.add(fake_episode(10 + k, seed=k)) for k in range(3)] == [0, 1, 2]
    with DatasetWriter(root) as writer:  # append: a new file, as LeRobot's writer resumes
        assert writer.add(fake_episode(7, seed=9)) == 3
    read = layout.check(root)
    assert read["info"]["total_episodes"] == 4
    assert read["info"]["total_frames"] == 10 + 11 + 12 + 7
    assert [e["data/file_index"] for e in read["episodes"]] == [0, 0, 0, 1]
    assert read["tasks"] == {0: "fake.dial in scene nowhere"}


def test_the_aggregate_stats_are_those_of_all_frames(tmp_path: Path) -> None:
    episodes = [fake_episode(12 + 5 * k, seed=k) for k in range(3)]
    with DatasetWriter(tmp_path / "a") as writer:
        writer.add(episodes[0])
    with DatasetWriter(tmp_path / "a") as writer:  # stats go on from stats.json
        writer.add(episodes[1])
        writer.add(episodes[2])
    stats = json.loads((tmp_path / "a/meta/stats.json").read_text())
    state = np.concatenate([e.columns["observation.state"] for e in episodes]).astype(np.float64)
    got = stats["observation.state"]
    assert got["count"] == [len(state)]
    np.testing.assert_allclose(got["mean"], state.mean(axis=0), rtol=1e-12)
    np.testing.assert_allclose(got["std"], state.std(axis=0), rtol=1e-9)
    np.testing.assert_array_equal(got["min"], state.min(axis=0))
    np.testing.assert_array_equal(got["max"], state.max(axis=0))
    tactile = np.concatenate([e.columns["observation.tactile"] for e in episodes]).astype(float)
    assert stats["observation.tactile"]["count"] == [len(tactile)]  # frames, as LeRobot counts
    np.testing.assert_allclose(  # one per index of the last axis, as LeRobot keeps them
        stats["observation.tactile"]["mean"], tactile.reshape(-1, 3).mean(axis=0), rtol=1e-6
    )
    assert stats["timestamp"]["max"] == [pytest.approx((12 + 10 - 1) / 50, abs=1e-6)]


def test_data_files_roll_over_at_the_size_limit(tmp_path: Path) -> None:
    with DatasetWriter(tmp_path / "r", file_mb=0.004) as writer:  # about 4 KB per file
        for k in range(6):
            writer.add(fake_episode(30, seed=k))
    read = layout.check(tmp_path / "r")
    files_of = [e["data/file_index"] for e in read["episodes"]]
    assert len(set(files_of)) > 1, files_of
    assert files_of == sorted(files_of)
    assert len(list((tmp_path / "r/data/chunk-000").glob("*.parquet"))) == len(set(files_of))


def test_another_feature_set_is_refused_naming_the_difference(tmp_path: Path) -> None:
    with DatasetWriter(tmp_path / "d") as writer:
        writer.add(fake_episode())
    before = digest(tmp_path / "d")
    with DatasetWriter(tmp_path / "d") as writer, pytest.raises(DatasetError) as e:
        writer.add(fake_episode(bodies=("box", "cup")))
    assert "observation.environment_state" in str(e.value)
    assert "names[7] is (none) in the dataset, cup_x in this run" in str(e.value)
    assert "\n" not in str(e.value)
    assert digest(tmp_path / "d") == before


@pytest.mark.parametrize("fps", [0, -5, 101, 2.5])
def test_a_bad_fps_is_one_line(tmp_path: Path, fps: int) -> None:
    with pytest.raises(OptionError, match=r"^--fps must be a whole number from 1 to 100"):
        DatasetWriter(tmp_path / "x", fps=fps)
    assert not (tmp_path / "x").exists()


def test_a_file_a_foreign_folder_and_another_fps_are_refused(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    with pytest.raises(DatasetError, match="is a file"):
        DatasetWriter(tmp_path / "file")
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("x")
    with pytest.raises(DatasetError, match="holds other files and no LeRobot dataset"):
        DatasetWriter(tmp_path / "other")
    with DatasetWriter(tmp_path / "d") as writer:
        writer.add(fake_episode())
    with pytest.raises(DatasetError, match=r"it is at 50 fps, not 30 \(give --fps 50\)"):
        DatasetWriter(tmp_path / "d", fps=30)


def test_a_second_writer_is_kept_out_while_one_writes(tmp_path: Path) -> None:
    with DatasetWriter(tmp_path / "d") as writer:
        writer.add(fake_episode())
        with pytest.raises(DatasetError, match="another process is writing"):
            DatasetWriter(tmp_path / "d")
    with DatasetWriter(tmp_path / "d") as writer:  # free again
        writer.add(fake_episode())


def _fail_at(monkeypatch: pytest.MonkeyPatch, target: object, name: str, after: int) -> None:
    """``target.name`` raises ENOSPC from its ``after+1``-th call on, as a full disk."""
    real = getattr(target, name)
    calls = [0]

    def failing(*args: object, **kwargs: object) -> object:
        calls[0] += 1
        if calls[0] > after:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(*args, **kwargs)

    monkeypatch.setattr(target, name, failing)


@pytest.mark.parametrize(
    ("where", "name", "after"),
    [("tables", "frames_table", 1), ("files", "write_json", 0), ("episode_row", "", 1)],
)
def test_a_full_disk_rolls_back_to_the_last_commit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, where: str, name: str, after: int
) -> None:
    root = tmp_path / "d"
    with DatasetWriter(root) as writer:
        writer.add(fake_episode(seed=1))
    before = digest(root)
    if where == "tables":
        _fail_at(monkeypatch, tables, name, after)
    elif where == "files":
        _fail_at(monkeypatch, files, name, after)
    else:
        _fail_at(monkeypatch, tables, "episode_row", after)
    with pytest.raises(DatasetError) as e, DatasetWriter(root) as writer:
        writer.add(fake_episode(seed=2))
        writer.add(fake_episode(seed=3))
    message = str(e.value)
    assert "No space left on device" in message and "\n" not in message
    assert "it holds 1 episodes as before" in message
    assert digest(root) == before
    layout.check(root)


def test_a_full_disk_on_a_new_dataset_leaves_no_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _fail_at(monkeypatch, files, "write_json", 0)
    with (
        pytest.raises(DatasetError, match="nothing was written"),
        DatasetWriter(tmp_path / "a" / "b") as writer,
    ):
        writer.add(fake_episode())
    assert list(tmp_path.iterdir()) == []


def test_an_interrupt_inside_a_write_keeps_the_whole_episodes_before_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    root = tmp_path / "d"
    real = tables.episode_row

    def interrupted(*args: object) -> object:
        if interrupted.calls == 2:  # type: ignore[attr-defined]
            raise KeyboardInterrupt
        interrupted.calls += 1  # type: ignore[attr-defined]
        return real(*args)  # type: ignore[arg-type]

    interrupted.calls = 0  # type: ignore[attr-defined]
    monkeypatch.setattr(tables, "episode_row", interrupted)
    with pytest.raises(KeyboardInterrupt), DatasetWriter(root) as writer:
        writer.add(fake_episode(seed=1))
        writer.commit()  # a commit point, as when a data file is full
        writer.add(fake_episode(seed=2))
        writer.add(fake_episode(seed=3))  # interrupted: rolls back to the commit
    assert layout.check(root)["info"]["total_episodes"] == 1


def test_stale_temporary_files_of_a_dead_writer_are_removed(tmp_path: Path) -> None:
    root = tmp_path / "d"
    with DatasetWriter(root) as writer:
        writer.add(fake_episode())
    stale = root / "data/chunk-000/.file-001.parquet.tmp"
    stale.write_bytes(b"half")
    with DatasetWriter(root) as writer:
        writer.add(fake_episode(seed=4))
    assert not stale.exists()
    layout.check(root)


def test_the_checker_catches_what_lerobots_reader_lets_through(tmp_path: Path) -> None:
    """A wrong total_frames, timestamps off the grid, a declared feature that is missing."""
    import pyarrow.parquet as pq

    def fresh(name: str) -> Path:
        with DatasetWriter(tmp_path / name) as writer:
            writer.add(fake_episode())
        return tmp_path / name

    root = fresh("total")
    info = json.loads((root / "meta/info.json").read_text())
    info["total_frames"] += 1
    (root / "meta/info.json").write_text(json.dumps(info))
    with pytest.raises(AssertionError):
        layout.check(root)

    for name in ("grid", "missing"):
        root = fresh(name)
        path = root / "data/chunk-000/file-000.parquet"
        table = pq.read_table(path)
        if name == "grid":
            shifted = table.column("timestamp").to_numpy() + np.float32(0.001)
            table = table.set_column(
                table.schema.get_field_index("timestamp"), "timestamp", [shifted]
            )
        else:
            table = table.drop_columns(["observation.velocity"])
        pq.write_table(table, path)
        with pytest.raises(AssertionError):
            layout.check(root)


def test_a_task_is_committed_with_its_first_episode(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The episode that fills a data file commits the file; a new task of the next episode,
    whose write then fails, is not in the dataset."""
    from dataclasses import replace

    _fail_at(monkeypatch, tables, "frames_table", 1)
    with pytest.raises(DatasetError), DatasetWriter(tmp_path / "d", file_mb=0.0001) as writer:
        writer.add(fake_episode(seed=1))
        writer.add(replace(fake_episode(seed=2), task="another task"))
    read = layout.check(tmp_path / "d")
    assert read["info"]["total_episodes"] == 1
    assert read["tasks"] == {0: "fake.dial in scene nowhere"}
