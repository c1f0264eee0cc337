"""The Python API: docs/api.md's examples run as written, and the API's errors are clear."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

import dial

from .conftest import ROOT

API_DOC = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
EXAMPLES = re.findall(r"```python\n(.*?)```", API_DOC, flags=re.S)


def test_the_docs_have_three_examples() -> None:
    assert len(EXAMPLES) == 3


@pytest.mark.parametrize("example", EXAMPLES, ids=["run", "observer", "dataset"])
def test_each_example_runs_as_written(example: str, tmp_path: object) -> None:
    done = subprocess.run(
        [sys.executable, "-c", example], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[-1].endswith("True")  # the examples end by printing a check that holds


def test_import_dial_does_not_load_mujoco() -> None:
    code = "import sys, dial; dial.load('pour.dial'); print('mujoco' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip() == "False", done.stderr


def test_public_names() -> None:
    for name in ("load", "run", "RunResult", "Observer", "Watched", "Script", "DialError"):
        assert hasattr(dial, name), name
    assert issubclass(dial.OptionError, dial.DialError)
    assert issubclass(dial.ScriptError, dial.DialError)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"tick": float("nan")}, "--tick must be above 0 s and at most 60 s (as @tick), got nan"),
        ({"tick": 1e9}, "--tick must be above 0 s and at most 60 s (as @tick), got 1e+09"),
        ({"seed": -1}, "--seed must be 0 or more, got -1"),
        ({"perturb": -5.0}, "--perturb must be 0 mm or more, got -5"),
        ({"perturb": float("nan")}, "--perturb must be 0 mm or more, got nan"),
        ({"speed": 0.0}, "--speed must be a positive number, got 0"),
        ({"disturb": ["shove body=x"]}, "--disturb 'shove body=x': expected 'push' or 'sense'"),
        ({"record": "x.mp4"}, "--record writes a .rrd file, not 'x.mp4'"),
    ],
)
def test_bad_options_raise_option_error_before_running(
    options: dict[str, object], message: str
) -> None:
    with pytest.raises(dial.OptionError) as caught:
        dial.run("pour.dial", **options)  # type: ignore[arg-type]
    assert str(caught.value).startswith(message)


def test_a_script_error_lists_every_problem(tmp_path: object) -> None:
    from pathlib import Path

    path = Path(str(tmp_path)) / "bad.dial"
    path.write_text("@scene surface\n% a hand_pose\n% b nonsense\nc #\n")
    with pytest.raises(dial.ScriptError) as caught:
        dial.load(path)
    assert len(caught.value.diagnostics) == 3
    assert f"{path}:3:5: unknown instruction 'nonsense'" in str(caught.value)
