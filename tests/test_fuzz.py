"""A seeded share of ``benchmarks/fuzz_check.py``: mutated scripts through check, show and fmt
end in a result or a script error, never an internal error or a hang (issue 15)."""

from __future__ import annotations

import importlib.util
import sys
from types import ModuleType

from .conftest import ROOT


def _fuzz_module() -> ModuleType:
    path = ROOT / "benchmarks" / "fuzz_check.py"
    spec = importlib.util.spec_from_file_location("fuzz_check", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["fuzz_check"] = module  # dataclasses look their module up by name
    spec.loader.exec_module(module)
    return module


def test_a_seeded_share_of_the_fuzz_benchmark() -> None:
    fuzz = _fuzz_module()
    # A hang is a loop that never ends; 10 s (not the benchmark's 2 s) keeps a busy machine
    # from failing the test.
    tally = fuzz.fuzz(inputs=2000, seed=15, timeout=10.0)
    failures = "\n\n".join(
        f"[{seed}] {kind}\n{text[:500]!r}" for kind, seed, text in tally.failures
    )
    assert tally.internal == 0 and tally.hangs == 0, failures
    assert tally.accepted > 100 and tally.rejected > 500  # both paths are exercised
