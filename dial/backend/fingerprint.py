"""The name of the IK memo's file (:mod:`dial.robot.memo`): a fingerprint of everything a
solution depends on besides its inputs.

That is the compiled IK model (its MJB bytes), the source of the solver's modules, the
versions of MuJoCo, numpy and Python, the installed files of mink, qpsolvers and daqp (by
size and modification time, without importing them) and the machine (``os.uname``).
"""

from __future__ import annotations

import hashlib
import os
import sys
from collections.abc import Iterable
from functools import cache
from importlib.util import find_spec
from pathlib import Path

import mujoco
import numpy as np

from dial.robot.memo import cache_dir

FORMAT = b"dial-ik-memo-1"
_SOLVER_PACKAGES = ("mink", "qpsolvers", "daqp")


def fingerprint(model: mujoco.MjModel, sources: Iterable[str]) -> str | None:
    """The name of the memo's file for solvers on ``model`` whose code is in ``sources``;
    None when the cache is off."""
    if cache_dir() is None:
        return None
    h = hashlib.sha256(_setting(tuple(sorted(sources))))
    mjb = np.zeros(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, mjb)
    h.update(mjb.tobytes())
    return h.hexdigest()[:32]


@cache
def _setting(sources: tuple[str, ...]) -> bytes:
    """What a solution depends on besides its model and inputs, once per process: the
    format, Python, MuJoCo and numpy, the machine, the solvers' code and packages."""
    machine = os.uname() if hasattr(os, "uname") else (sys.platform,)
    parts = [FORMAT, *(s.encode() for s in (sys.version, mujoco.__version__, np.__version__))]
    parts += [s.encode() for s in machine]
    parts += [Path(source).read_bytes() for source in sources]
    parts += [_installed(package).encode() for package in _SOLVER_PACKAGES]
    return hashlib.sha256(b"\0".join(parts)).digest()


def _installed(package: str) -> str:
    """The installed files of ``package`` by size and modification time (not imported)."""
    spec = find_spec(package)
    if spec is None or spec.origin is None:
        return f"{package}: missing"
    if not spec.submodule_search_locations:  # a module: its file
        return _stat(spec.origin)
    found = []
    for folder, _, files in os.walk(os.path.dirname(spec.origin)):  # a package: its folder
        found += [_stat(os.path.join(folder, f)) for f in files if not f.endswith(".pyc")]
    return "\n".join(sorted(found))


def _stat(path: str) -> str:
    try:
        st = os.stat(path)
    except OSError:
        return f"{path}: missing"
    return f"{path}:{st.st_size}:{st.st_mtime_ns}"
