"""Parse and check generated scripts and print the times (issues 2 and 15).

Targets, on the project's 2-core machine:
  - a 10,000-line script: under 0.5 s (issue 2);
  - a 10 MB valid script: at most 5 s; three nested ``@repeat 1000``: under 1 s;
    a line of 100,000 ``#``: under 1 s (issue 15).

    python benchmarks/bench_parse.py [--lines N] [--megabytes M] [--repeat R]

Each figure is the best and the median of R runs of ``check_text`` and freeing its result,
as ``dial check`` does, in wall and CPU time; then the time of one full garbage collection
with the result alive (what a long-lived process pays for keeping it, spread over time).
The load average is printed: on a busy machine, wall time says little.
"""

from __future__ import annotations

import argparse
import gc
import os
import time
from collections.abc import Callable

from dial.parser import check_text, expand
from dial.parser.timeline import length

DEFINITIONS = """\
% go    puma_command   "moves above"
% back  puma_command   "depart 50mm"
% pre   hand_pose      "open_hand"
% pt    hand_pose      "point" fingers=0x000F
% grab  grasp_force    "0x0666_0x0222 4N" timeout=5s
% down  guarded_move   finger=index 0 0 -20mm until=tactile:0.1mm max=25mm
% touch tactile_contact finger=index threshold=0.1mm
% rec   record_contact finger=index into=surface
% fit   fit_plane      surface
"""

BLOCK = """\
// a block with concurrent arm and hand events
go    #=========
pre        #----
grab            #
back             #====
rec                  #
@repeat until !touch max 20
down  #
rec    #
@end

"""


def generate(lines: int) -> str:
    text = DEFINITIONS
    per_block = BLOCK.count("\n")
    while text.count("\n") < lines:
        text += BLOCK
    assert text.count("\n") >= lines - per_block
    return text


def megabytes(mb: float) -> str:
    """A valid script of about ``mb`` MB: the same block again and again."""
    return DEFINITIONS + BLOCK * (int(mb * 1_000_000) // len(BLOCK) + 1)


CASES: dict[str, Callable[[argparse.Namespace], str]] = {
    "10,000 lines": lambda a: generate(a.lines),
    "10 MB": lambda a: megabytes(a.megabytes),
    "3 nested @repeat 1000": lambda a: (
        DEFINITIONS + "@repeat 1000\n@repeat 1000\n@repeat 1000\ngo #\n@end\n@end\n@end\n"
    ),
    "a line of 100,000 #": lambda a: DEFINITIONS + "go " + "#" * 100_000 + "\n",
}
TARGETS = {"10,000 lines": 0.5, "10 MB": 5.0, "3 nested @repeat 1000": 1.0}
TARGETS["a line of 100,000 #"] = 1.0


def timed(text: str) -> tuple[float, float]:
    """Wall and CPU seconds of one check and of freeing its result."""
    gc.collect()
    wall, cpu = time.perf_counter(), time.process_time()
    check_text(text, "generated.dial")
    return time.perf_counter() - wall, time.process_time() - cpu


def collection(text: str) -> float:
    """Seconds of one full garbage collection while the checked script is alive."""
    script = check_text(text, "generated.dial")
    start = time.perf_counter()
    gc.collect()
    seconds = time.perf_counter() - start
    del script
    return seconds


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--lines", type=int, default=10_000)
    ap.add_argument("--megabytes", type=float, default=10.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print("load average: " + ", ".join(f"{x:.1f}" for x in os.getloadavg()))
    for name, make in CASES.items():
        text = make(args)
        runs = sorted(timed(text) for _ in range(args.repeat))
        (best, best_cpu), (median, median_cpu) = runs[0], runs[len(runs) // 2]
        ticks = length(check_text(text, "generated.dial"))
        target = TARGETS[name]
        print(
            f"{name:24s} {len(text) / 1e6:6.2f} MB, {ticks:>13} ticks: best {best:.3f} s"
            f" (cpu {best_cpu:.3f}), median {median:.3f} s (cpu {median_cpu:.3f});"
            f" target < {target:g} s {'met' if median < target else 'NOT met'};"
            f" then a full collection {collection(text):.3f} s"
        )
    layout = expand(check_text(generate(args.lines), "generated.dial"))
    print(f"dial show of 10,000 lines: {len(layout.runs)} runs on {layout.length} ticks")


if __name__ == "__main__":
    main()
