"""Parse and check a generated 10,000-line script and print the time.

Target (issue 2): under 0.5 s on the project's 2-core machine.

    python benchmarks/bench_parse.py [--lines N] [--repeat R]
"""

from __future__ import annotations

import argparse
import time

from dial.parser import check_text, expand

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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--lines", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    text = generate(args.lines)
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        script = check_text(text, "generated.dial")
        times.append(time.perf_counter() - t0)
    assert script is not None
    layout = expand(script)
    best, median = min(times), sorted(times)[len(times) // 2]
    print(f"script: {text.count(chr(10))} lines, {len(layout.runs)} runs on {layout.length} ticks")
    print(f"parse+check: best {best:.3f} s, median {median:.3f} s over {args.repeat} runs")
    print(f"target < 0.5 s: {'met' if median < 0.5 else 'NOT met'}")


if __name__ == "__main__":
    main()
