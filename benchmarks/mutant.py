"""The pathological input of issue 26: scripts/explore.dial with one 300 KB line.

The line is a definition given 75,000 unknown parameters (``% g get_joints y=1 y=1 ...``,
the fuzzer's ``LINES`` mutation of benchmarks/fuzz_check.py grown large), so the file has
75,000 problems on one line. ``dial check`` reports the first 100 (``dial.errors.MAX_PROBLEMS``)
and says how many lines it did not check; the target is 0.5 s for the whole process.

    python benchmarks/mutant.py DIR    # writes DIR/explore_mutant.dial beside copies of the
                                       # scripts it calls, and prints its path
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCRIPTS = ROOT / "scripts"
PROBLEMS = 75_000
NAME = "explore_mutant.dial"


def mutant_text(problems: int = PROBLEMS) -> str:
    """explore.dial with the long definition after its last one."""
    lines = (SCRIPTS / "explore.dial").read_text(encoding="utf-8").split("\n")
    last = max(i for i, line in enumerate(lines) if line.startswith("%"))
    lines.insert(last + 1, "% g get_joints " + "y=1 " * problems)
    return "\n".join(lines)


def write_mutant(folder: Path, problems: int = PROBLEMS) -> Path:
    """Write the mutant into ``folder`` with the bundled scripts (its calls resolve there)."""
    folder.mkdir(parents=True, exist_ok=True)
    for script in SCRIPTS.glob("*.dial"):
        shutil.copy(script, folder / script.name)
    path = folder / NAME
    path.write_text(mutant_text(problems), encoding="utf-8")
    return path


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    print(write_mutant(Path(sys.argv[1])))
