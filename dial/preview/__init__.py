"""``dial preview``: a kinematic dry run of a script, with no contact dynamics.

Every arm target is solved and every hand pose set, in order, from the world's ``home``;
reachability, joint limits and collisions are checked, and each problem is reported at the
script line that causes it. See docs/debugging.md.
"""

from __future__ import annotations

from pathlib import Path

from dial.backend.driver import CONTROL_PERIOD
from dial.parser.script import Script
from dial.preview.report import Counts, PreviewResult
from dial.preview.scene import Scene
from dial.preview.walk import Walk
from dial.scene.of_script import script_world
from dial.scheduler.types import DEFAULT_TICK, periods_per_tick


def preview(script: Script, storyboard: Path | None = None) -> PreviewResult:
    """Preview ``script`` in its scene; with ``storyboard``, draw a panel per block there."""
    scene = Scene(script_world(script), textures=storyboard is not None)
    ticks = periods_per_tick(script.tick or DEFAULT_TICK, CONTROL_PERIOD)
    walk = Walk(scene, ticks, traces=storyboard is not None)
    walk.steps(script, script.timeline, "")
    panels = 0
    if storyboard is not None:
        from dial.preview.storyboard import draw

        panels = draw(scene, walk.panels, storyboard, Path(script.path).name)
    lines = walk.problems.lines()
    count = walk.problems.count
    return PreviewResult(script.path, lines[:count], lines[count:], walk.counts, panels)


__all__ = ["Counts", "PreviewResult", "preview"]
