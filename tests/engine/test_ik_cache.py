"""The IK's cache in the user's cache folder (dial.robot.memo, issue 26): what it keeps,
when it is read again, that it never changes a result, and that it survives a bad folder."""

from __future__ import annotations

import copy
import json
import marshal
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dial.backend.fingerprint import fingerprint
from dial.backend.ik import ArmIK
from dial.backend.model import ARM_HOME, load_model
from dial.robot import memo
from tests.conftest import ROOT, SHORT

IK_SOURCE = str(ROOT / "dial" / "backend" / "ik.py")


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("DIAL_CACHE", str(tmp_path))
    return tmp_path / "ik"


def test_a_memo_keeps_arrays_and_failures_on_disk_and_the_rest_in_process(cache: Path) -> None:
    first = memo.Memo("f" * 32)
    q = np.array([0.1, -0.2, 0.3])
    first.put(memo.memo_key("arm-solve", q, 2), q)
    first.put(memo.memo_key("arm-solve", q, 3), (1.5, 0.25))  # a target out of reach
    first.put(memo.memo_key("arm-line", q), object())  # a line's segment: this process only
    first.put(("arm-solve", np.int64(4)), q)  # a key marshal cannot keep: this process only
    first.save()
    second = memo.Memo("f" * 32)
    known = second.get(memo.memo_key("arm-solve", q, 2))
    assert isinstance(known, np.ndarray) and known.tobytes() == q.tobytes()
    assert second.get(memo.memo_key("arm-solve", q, 3)) == (1.5, 0.25)
    assert second.get(memo.memo_key("arm-line", q)) is None
    assert second.get(("arm-solve", 4)) is None
    assert memo.Memo("e" * 32).get(memo.memo_key("arm-solve", q, 2)) is None  # another file


def test_a_damaged_file_is_a_miss_and_is_written_again(cache: Path) -> None:
    cache.mkdir(parents=True)
    path = cache / f"{'d' * 32}.marshal"
    path.write_bytes(b"\x00 not a memo")
    damaged = memo.Memo("d" * 32)
    key = memo.memo_key("arm-track", np.ones(3))
    assert damaged.get(key) is None
    odd = {key: b"\x00" * 7, memo.memo_key("arm-solve", np.ones(3)): ("far", 0.5)}
    path.write_bytes(marshal.dumps(odd))  # marshal's, but not as the memo writes them
    assert memo.Memo("d" * 32).get(key) is None
    assert memo.Memo("d" * 32).get(memo.memo_key("arm-solve", np.ones(3))) is None
    damaged.put(key, np.ones(6))
    damaged.save()
    assert isinstance(memo.Memo("d" * 32).get(key), np.ndarray)


def test_a_folder_that_cannot_be_made_is_no_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "file").write_text("")
    monkeypatch.setenv("DIAL_CACHE", str(tmp_path / "file"))
    lost = memo.Memo("c" * 32)
    lost.put(memo.memo_key("arm-track", np.ones(3)), np.ones(6))
    lost.save()  # nothing written, nothing raised
    assert memo.Memo("c" * 32).get(memo.memo_key("arm-track", np.ones(3))) is None


def test_the_file_keeps_the_newest_entries(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(memo, "MAX_SAVED", 3)
    old = memo.Memo("b" * 32)
    for k in range(5):
        old.put(memo.memo_key("arm-track", np.full(3, k)), np.full(6, k, dtype=np.float64))
    old.save()
    kept = memo.Memo("b" * 32)
    found = [kept.get(memo.memo_key("arm-track", np.full(3, k))) is not None for k in range(5)]
    assert found == [False, False, True, True, True]


def test_the_file_is_named_after_the_model_the_code_and_the_cache_setting(
    cache: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    model = load_model()
    name = fingerprint(model, [IK_SOURCE])
    assert name == fingerprint(load_model(), [IK_SOURCE])  # compiled again: the same
    heavier = copy.copy(model)
    heavier.body_mass[1] += 0.001
    assert fingerprint(heavier, [IK_SOURCE]) != name  # an edited model
    edited = tmp_path / "ik.py"
    edited.write_text(Path(IK_SOURCE).read_text() + "\n# DAMPING changed\n")
    assert fingerprint(model, [str(edited)]) != name  # edited solver code
    monkeypatch.setenv("DIAL_CACHE", "off")
    assert fingerprint(model, [IK_SOURCE]) is None
    assert memo.cache_dir() is None


def test_a_solve_from_the_file_is_the_solve_to_the_bit(cache: Path) -> None:
    solver = ArmIK()
    home = np.array(ARM_HOME)
    pos, rot = solver.fk(home + 0.05)
    fresh = solver.solve(pos, rot, home, "x")
    goals = [pos + np.array([0.0, 0.0, 0.01 * k]) for k in range(3)]
    line = [solver.track(goal, rot, fresh, 2) for goal in goals]
    solver.memo.save()
    again = memo.Memo(solver.memo.fingerprint)  # a later process: this file, no solves
    assert solver.memo.fingerprint is not None
    assert np.asarray(
        again.get(memo.memo_key(f"{solver.MEMO}-solve", pos, rot, home))
    ).tobytes() == (fresh.tobytes())
    tracked = [
        again.get(memo.memo_key(f"{solver.MEMO}-track", goal, rot, fresh, 2)) for goal in goals
    ]
    assert [np.asarray(t).tobytes() for t in tracked] == [q.tobytes() for q in line]


def _logged_run(script: Path, cache: Path, log: Path) -> list[dict[str, object]]:
    env = dict(os.environ, DIAL_CACHE=str(cache))
    args = ["run", str(script), "--perturb", "5", "--seed", "2", "--quiet", "--log", str(log)]
    done = subprocess.run([sys.executable, "-m", "dial.cli", *args], env=env, timeout=300)
    assert done.returncode in (0, 1)  # 1: a criterion of the surface scene fails here
    records = [json.loads(line) for line in log.read_text().splitlines()]
    for record in records:
        record.pop("wall_time", None)
    return records


def test_a_run_from_the_cache_logs_what_a_run_without_it_logs(tmp_path: Path) -> None:
    script = tmp_path / "short.dial"
    script.write_text(SHORT)
    cold = _logged_run(script, tmp_path / "cache", tmp_path / "cold.jsonl")
    assert list((tmp_path / "cache" / "ik").glob("*.marshal"))  # the run wrote its solves
    warm = _logged_run(script, tmp_path / "cache", tmp_path / "warm.jsonl")
    assert warm == cold
    assert cold[-1]["kind"] == "summary" and len(cold) > 10
