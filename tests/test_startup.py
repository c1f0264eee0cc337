"""Which heavy packages each command loads (issue 26, DESIGN 7: latency a person feels).

Each command runs as the ``dial`` program does, in a fresh process under
``python -X importtime``; the heavy packages it loaded are compared with what it needs. A
failure names the chain of imports that brought the package in, innermost first (read it
right to left: the last module is the one this command imported)."""

from __future__ import annotations

import gc
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT, SHORT

HEAVY = ("mujoco", "scipy", "rerun", "mink", "qpsolvers", "trio", "pyarrow", "ray", "matplotlib")
DATASET = "dial.dataset"  # counted as heavy too: it is for --dataset alone
PROGRAM = "import sys; from dial.cli import main; sys.exit(main())"  # as the installed `dial`
POUR = str(ROOT / "scripts" / "pour.dial")
RUN_NEEDS = {"mujoco", "trio"}  # the physics and the runner
SOLVING = {"mink", "qpsolvers", "scipy"}  # IK problems not in the IK's cache (qpsolvers: SciPy)


def chains(report: str) -> dict[str, str]:
    """The heavy packages ``python -X importtime`` reports, and for each the chain of imports
    that first brought it in (``a <- b`` : ``b`` imported ``a``)."""
    rows: list[tuple[int, str]] = []  # (nesting, module), children before their parents
    for line in report.splitlines():
        if line.startswith("import time:") and line.count("|") == 2:
            name = line.split("|")[2]
            if name.strip() != "imported package":
                rows.append(((len(name) - len(name.lstrip()) - 1) // 2, name.strip()))
    found: dict[str, str] = {}
    for i, (depth, name) in enumerate(rows):
        top = DATASET if f"{name}.".startswith(f"{DATASET}.") else name.split(".")[0]
        if (top in HEAVY or top == DATASET) and top not in found:
            chain = [name]
            for outer, importer in rows[i + 1 :]:
                if outer < depth:
                    chain.append(importer)
                    depth = outer
            found[top] = " <- ".join(chain)
    return found


def loads(args: list[str], cache: Path, program: str = PROGRAM) -> dict[str, str]:
    """The heavy packages ``dial ARGS`` loads, with their chains; ``cache``: DIAL_CACHE."""
    env = dict(os.environ, DIAL_CACHE=str(cache))
    done = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", program, *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    problems = [line for line in done.stderr.splitlines() if not line.startswith("import time:")]
    assert done.returncode in (0, 1) and "Traceback" not in done.stderr, "\n".join(problems)
    return chains(done.stderr)


def expect(loaded: dict[str, str], needed: set[str], what: str) -> None:
    extra = {name: chain for name, chain in loaded.items() if name not in needed}
    assert not extra, f"{what} loads what it does not need:\n" + "\n".join(
        f"  {name}: {chain}" for name, chain in sorted(extra.items())
    )
    missing = needed - set(loaded)
    assert not missing, f"{what} should load {sorted(missing)} (is the test still measuring?)"


def test_the_chains_name_who_imported_what() -> None:
    report = "\n".join(
        [
            "import time: self [us] | cumulative | imported package",
            "import time:       100 |        100 |         mink.lie",
            "import time:       100 |        200 |       mink",
            "import time:       100 |        300 |     dial.backend.ik",
            "import time:       100 |        400 |   dial.primitives",
            "import time:       100 |        500 | dial.engine",
            "import time:       100 |        100 | trio",
        ]
    )
    assert chains(report) == {
        "mink": "mink.lie <- mink <- dial.backend.ik <- dial.primitives <- dial.engine",
        "trio": "trio",
    }


def test_import_dial_loads_nothing_but_itself(tmp_path: Path) -> None:
    program = "import sys, dial; print(sorted(m for m in sys.modules if m.startswith('dial.')))"
    done = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", program],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    # what makes the names lazy, and the cache of the dataclasses' code (with its folder)
    assert done.stdout.strip() == "['dial.codecache', 'dial.lazy', 'dial.usercache']"
    expect(chains(done.stderr), set(), "import dial")


@pytest.mark.parametrize(
    ("args", "drawing"),
    [
        (["run", POUR], False),
        (["run", POUR, "--dataset", "d"], False),
        (["run", POUR, "--dataset", "d", "--cameras", "task"], True),
        (["tune", POUR, "--ticks", "0.1:0.2:2", "--dataset", "d", "--cameras", "task"], True),
        (["run", POUR, "--video", "v.mp4"], True),
        (["run", POUR, "--viewer"], True),
        (["preview", POUR, "--storyboard", "s.png"], True),
        (["world", "pour", "--picture", "p.png"], True),
        (["teach", "--scene", "surface", "--snapshot", "d"], True),
        (["teach", "--scene", "surface"], False),
        (["replay", "run.jsonl", "--video", "v.mp4"], True),
        (["check", POUR], False),
    ],
)
def test_the_program_lets_mujoco_find_opengl_only_when_an_option_draws(
    args: list[str], drawing: bool
) -> None:
    from dial.cli import build_parser, draws

    assert draws(build_parser().parse_args(args)) is drawing


@pytest.mark.parametrize(
    "args",
    [["--help"], ["check", POUR], ["show", POUR], ["fmt", "--check", POUR], ["run", "--help"]],
    ids=["help", "check", "show", "fmt", "run-help"],
)
def test_the_commands_on_text_load_no_heavy_package(args: list[str], tmp_path: Path) -> None:
    expect(loads(args, tmp_path), set(), f"dial {' '.join(args)}")


def test_a_run_loads_the_ik_solvers_for_new_problems_only_and_pyarrow_for_datasets(
    tmp_path: Path,
) -> None:
    script = tmp_path / "short.dial"
    script.write_text(SHORT)
    cache = tmp_path / "cache"
    run = ["run", str(script), "--quiet"]
    expect(loads(run, cache), RUN_NEEDS | SOLVING, "dial run (an empty IK cache)")
    expect(loads(run, cache), RUN_NEEDS, "dial run (its IK problems in the cache)")
    if importlib.util.find_spec("pyarrow") is not None:  # the 'dataset' extra (in 'test')
        dataset = [*run, "--dataset", str(tmp_path / "data")]
        expect(loads(dataset, cache), RUN_NEEDS | {"pyarrow", DATASET}, "dial run --dataset")
        assert (tmp_path / "data" / "meta" / "info.json").is_file()  # it wrote the episode
    (tmp_path / "a_file").write_text("")  # a cache folder that cannot be made: still runs
    expect(loads(run, tmp_path / "a_file"), RUN_NEEDS | SOLVING, "dial run, no cache folder")


def test_scipy_loads_when_a_script_fits_and_rerun_when_a_run_records(tmp_path: Path) -> None:
    script = tmp_path / "fit.dial"
    script.write_text("@scene surface\n@tick 0.1\n% fit fit_plane pts\nfit #\n")
    cache = tmp_path / "cache"
    loads(["run", str(script), "--quiet"], cache)  # the start pose into the cache
    loaded = loads(["run", str(script), "--quiet"], cache)
    assert "scipy.optimize" in loaded["scipy"] or "dial.haptics" in loaded["scipy"], loaded
    expect(loaded, RUN_NEEDS | {"scipy"}, "dial run of a fit")
    record = ["run", str(script), "--quiet", "--record", str(tmp_path / "fit.rrd")]
    recording = {"rerun", "pyarrow"}  # rerun's own
    expect(loads(record, cache), RUN_NEEDS | {"scipy"} | recording, "dial run --record of a fit")


def test_the_preview_and_the_world_load_no_runner_and_no_solver_they_need_not(
    tmp_path: Path,
) -> None:
    cache = tmp_path / "cache"
    preview = ["preview", POUR]
    expect(loads(preview, cache), {"mujoco"} | SOLVING, "dial preview (an empty IK cache)")
    expect(loads(preview, cache), {"mujoco"}, "dial preview (its IK problems in the cache)")
    expect(loads(["world", "pour"], cache), {"mujoco"}, "dial world")


@pytest.mark.parametrize(
    ("args", "collecting"),
    [
        (["check", POUR], False),
        (["preview", POUR], False),
        (["run", "short"], True),
        (["replay", "no_such.jsonl"], True),  # any command that is not QUICK
    ],
    ids=["check", "preview", "run", "replay"],
)
def test_the_program_collects_garbage_in_the_commands_that_run_on_and_lets_blas_sleep(
    args: list[str], collecting: bool, tmp_path: Path
) -> None:
    """The collector is off for the start-up (and a quick command, to its exit); a run
    turns it on before the scene is loaded, with what it made until then frozen."""
    if args == ["run", "short"]:
        (tmp_path / "short.dial").write_text(SHORT)
        args = ["run", str(tmp_path / "short.dial"), "--quiet"]
    program = (
        "import gc, os, sys; from dial.cli import main; assert 'numpy' not in sys.modules\n"
        "import dial.engine.setup as s; p = s.prepare\n"
        "def prepare(*a, **k):\n"
        "    print('at prepare', gc.isenabled(), gc.get_freeze_count() > 1000); return p(*a, **k)\n"
        "sys.modules['dial.engine.run'].prepare = prepare\n"
        "status = main(); print('at exit', gc.isenabled())\n"
        "print('OpenBLAS', os.environ.get('OPENBLAS_THREAD_TIMEOUT')); sys.exit(status)"
    )
    env = dict(os.environ, DIAL_CACHE=str(tmp_path))
    done = subprocess.run(
        [sys.executable, "-c", program, *args],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    said = done.stdout.splitlines()
    assert f"at exit {collecting}" in said, done.stdout + done.stderr
    assert "OpenBLAS 4" in said  # its idle threads sleep at once (set before numpy loads)
    if args[0] == "run":
        assert "at prepare True True" in said  # on, what start-up made frozen
    from dial.cli import main

    assert main(["check", POUR]) == 0 and gc.isenabled()  # called as a function: untouched
