"""The viewer's layout of a recording (a rerun blueprint), and the entity paths it shows.

Left: the event lanes, tall enough for 15 lanes in a 1000-pixel window, above the text log.
Right: the 3-D scene from an eye on the task's workspace; below it the task's measurements,
then the fingertip tactile images with their colour scale and the plots' colour key beside
the joints and tendons (tabs: hand joints per finger, tendon tensions per finger, arm
joints). Plots carry no legend over their data: their colours
are the key's, and hovering a line names it.
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun.blueprint as rrb
from rerun.blueprint.encodings import TextLogColumn, TimelineColumn

from dial.backend.model import FINGERS

Vec3 = tuple[float, float, float]

TACTILE, KEY, TASK, LOG = "tactile", "tactile/key", "task", "events/log"
HAND_JOINTS, ARM_JOINTS, TENDONS = "robot/hand", "robot/arm", "robot/tendons"
NOT_LANES = ("world", "tactile", "task", "robot", "events")  # every other root entity is a lane
COLUMN_SHARES = (2.0, 3.0)  # lanes and log | scene, tactile, task and robot
LEFT_SHARES = (7.0, 3.0)  # lanes, log: 1000 px high fit about 15 lanes
RIGHT_SHARES = (1.3, 0.45, 1.0)  # scene, task, tactile and robot
# taxels: four 16x16 images two by two with their names, the depth scale, the colour key
TACTILE_BOUNDS = ((-1.0, 59.0), (-1.0, 39.5))


def blueprint(
    eye: tuple[Vec3, Vec3] | None,
    task: Sequence[tuple[str, str]],
    loads: str = "tendons (N)",
) -> rrb.Blueprint:
    """The layout; ``eye`` (position, look target) in m, ``task`` (name, title) per series,
    ``loads`` the title of the hand's load plots."""
    controls = None
    if eye is not None:
        controls = rrb.EyeControls3D(position=eye[0], look_target=eye[1], eye_up=(0.0, 0.0, 1.0))
    lanes = rrb.StateTimelineView(
        origin="/",
        contents=["/**", *(f"- /{root}/**" for root in NOT_LANES)],
        name="events, in script order",
    )
    left = rrb.Vertical(
        lanes,
        rrb.TextLogView(origin=LOG, name="log", columns=_LOG_COLUMNS),
        row_shares=list(LEFT_SHARES),
    )
    tactile = rrb.Spatial2DView(
        origin=TACTILE,
        name="fingertip tactile: depth (mm)",
        visual_bounds=rrb.VisualBounds2D(x_range=TACTILE_BOUNDS[0], y_range=TACTILE_BOUNDS[1]),
    )
    robot = rrb.Tabs(
        _per_finger(HAND_JOINTS, "joints (rad)"),
        _per_finger(TENDONS, loads),
        rrb.TimeSeriesView(origin=ARM_JOINTS, name="arm joints (rad)", plot_legend=_NO_LEGEND),
        name="robot",
    )
    scene = rrb.Spatial3DView(origin="world", name="scene", eye_controls=controls)
    rest = rrb.Horizontal(tactile, robot)
    if task:
        right = rrb.Vertical(scene, _task(task), rest, row_shares=list(RIGHT_SHARES))
    else:  # a scene whose criteria all judge fits: nothing to plot while it runs
        shares = [RIGHT_SHARES[0], RIGHT_SHARES[1] + RIGHT_SHARES[2]]
        right = rrb.Vertical(scene, rest, row_shares=shares)
    return rrb.Blueprint(
        rrb.Horizontal(left, right, column_shares=list(COLUMN_SHARES)),
        rrb.TimePanel(timeline="sim_time", play_state="following", state="collapsed"),
        collapse_panels=True,
    )


_NO_LEGEND = rrb.PlotLegend(visible=False)
_LOG_COLUMNS = rrb.TextLogColumns(
    timeline_columns=[TimelineColumn("sim_time"), TimelineColumn("tick", visible=False)],
    text_log_columns=[
        TextLogColumn("loglevel"),
        TextLogColumn("body"),
        TextLogColumn("entitypath", visible=False),
    ],
)


def _per_finger(origin: str, what: str) -> rrb.Grid:
    views = [
        rrb.TimeSeriesView(origin=f"{origin}/{f}", name=f"{f} {what}", plot_legend=_NO_LEGEND)
        for f in FINGERS
    ]
    return rrb.Grid(*views, grid_columns=2, name=what.split(" (")[0])


def _task(task: Sequence[tuple[str, str]]) -> rrb.Container:
    """One plot per measurement, each titled with its quantity and unit."""
    views = [
        rrb.TimeSeriesView(origin=f"{TASK}/{name}", name=title, plot_legend=_NO_LEGEND)
        for name, title in task
    ]
    return rrb.Horizontal(*views, name="task")
