"""Every rerun call in dial but the layout's (:mod:`dial.recording.layout`): a run as a ``.rrd``
recording or a live stream to a viewer.

Entity paths:

- ``world``: the scene, z up, every geometry solid. ``world/<body>`` holds a body's pose in
  the world frame: ``world/arm/link2``, ``world/hand/index_distal`` (by the robot's name
  prefixes), a scene object by its alias (``world/bulb``), ``world/scene/<body>`` for the
  rest; ``world/<body>/<geom>`` its
  shapes (``world/hand/index_distal/pad``). ``world/contacts/guards/<n>`` where a guard
  stopped an effector (shown for two seconds), ``world/contacts/<set>`` the recorded contact
  points, ``world/fits/<set>`` fitted planes and superquadrics.
- ``robot/hand/<finger>`` its joint angles (rad), ``robot/arm`` the arm's joints (rad),
  ``robot/tendons/<finger>`` its joints' loads: a tendon hand's flexor and extensor tensions
  (N), another hand's joint torques (N m).
- ``tactile/<finger>``: the taxel depths in mm (16x16 on the bundled robots), fingertip up,
  side by side; ``tactile/key`` the depth colour scale and the plots' colours.
- ``task/<criterion>``: what the scene's criteria measure, over the run.
- ``events/log``: a text log of starts, ends, contacts, warnings and the criteria.
- ``<NN>_<event>``: the event lanes (:mod:`dial.recording.lanes`).

Two timelines: ``sim_time`` (simulated time) and ``tick`` (the absolute tick).
Body poses, joints, tensions, tactile images and measurements are sent as columns in batches
of frames: one call per entity per batch keeps the cost per frame to an array copy.
"""

from __future__ import annotations

import dataclasses
import socket
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import rerun as rr

from dial.backend.model import FINGERS, default_profile
from dial.errors import DialError
from dial.recording import layout
from dial.recording.frames import Batch
from dial.recording.geometry import body_paths, moving_bodies, shapes, superquadric_mesh
from dial.recording.lanes import STATE_COLORS, Lane, LanePlan, Lanes, Phase
from dial.recording.rerun_shapes import SOLID, archetype, quat
from dial.recording.styles import (
    EXTENSOR_SHADE,
    JOINT_COLORS,
    JOINTS,
    TASK_COLOR,
    arm_series,
    finger_series,
    shade,
)
from dial.recording.task import Series
from dial.recording.timeline import describe, when
from dial.robot.snapshot import FloatArray
from dial.robots.profile import RobotProfile

APP_ID = "dial"
TACTILE_MM = 1.0  # the colour scale's top: a firm press is 0.5-1 mm deep
TACTILE_GAP = 3  # taxels between two fingertips' images
GUARD_COLOR, POINT_COLOR, FIT_COLOR = (255, 80, 40), (40, 160, 255), (255, 200, 0, 140)
GUARD_SHOWN_S = 2.0  # simulated seconds a guard's contact marker stays
LEVELS = {"info": "INFO", "warn": "WARN", "error": "ERROR"}  # rerun's TextLogLevel
PLANE_THICKNESS = 1e-3  # m, to draw a fitted plane as a thin box
VIEWER_PORT = 9876  # rerun's default
FLUSH_TIMEOUT_S = 10.0


def _listening(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), timeout=1.0).close()
    except OSError:
        return False
    return True


class RerunSink:
    """A rerun recording stream to a ``.rrd`` file, a spawned viewer, or both."""

    def __init__(self, path: Path | None = None, spawn: bool = False) -> None:
        self.rec = rr.RecordingStream(APP_ID)
        # Only simulated time and ticks: no wall-clock timelines in the recording.
        rr.set_log_time_enabled(False, recording=self.rec)
        rr.set_log_tick_enabled(False, recording=self.rec)
        sinks: list[Any] = []
        if spawn:
            try:
                self.rec.spawn(port=VIEWER_PORT, connect=False)
            except Exception as e:  # rerun raises plain errors when the viewer cannot start
                raise DialError(f"--rerun could not start the rerun viewer: {e}") from e
            if not _listening(VIEWER_PORT):  # spawn only warns when the viewer dies at once
                raise DialError("--rerun: the rerun viewer did not start (is there a display?)")
            sinks.append(rr.GrpcSink(f"rerun+http://127.0.0.1:{VIEWER_PORT}/proxy"))
        if path is not None:
            sinks.append(rr.FileSink(str(path)))
        try:
            self.rec.set_sinks(*sinks)
        except RuntimeError as e:  # e.g. the file's directory does not exist
            raise DialError(f"cannot write the recording: {e}") from e
        self.batch = 25 if spawn else 250  # frames per send: live viewers want them sooner
        self.live = spawn
        self.lanes = Lanes()
        self._bodies: list[str] = []
        self._task: list[str] = []
        self._lanes_seen: set[tuple[str, ...]] = set()
        # Text lines and lane changes wait for the next batch of frames: one call per entity.
        self._lines: list[tuple[int, int, str, str]] = []  # ns, tick, text, level
        self._changes: dict[str, list[tuple[int, int, str]]] = {}  # lane: ns, tick, state
        self._points: dict[str, list[FloatArray]] = {}
        self._guards = 0
        self._profile = default_profile()

    # -- once ---------------------------------------------------------------------------------
    def scene(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        title: str,
        eye: tuple[layout.Vec3, layout.Vec3] | None,
        objects: Mapping[str, str],
        task: Sequence[Series] = (),
        plan: LanePlan | None = None,
        profile: RobotProfile | None = None,
    ) -> None:
        """Static geometry, series styles and the layout; ``data`` gives the fixed bodies'
        poses, ``objects`` the scene's object aliases, ``plan`` the script's event lanes,
        ``profile`` the robot (the default robot's when None)."""
        rec = self.rec
        self._profile = default_profile() if profile is None else profile
        self.lanes = Lanes(plan)
        self.open_lanes(self.lanes)
        self._task = [f"{layout.TASK}/{s.name}" for s in task]
        rec.send_recording_name(title)
        titles = [(s.name, f"{s.label} ({s.unit})") for s in task]
        loads = "tendons (N)" if self._profile.hand.load == "tendon" else "joint torques (N m)"
        rec.send_blueprint(layout.blueprint(eye, titles, loads))
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        paths = [f"world/{p}" for p in body_paths(model, objects, self._profile)]
        moving = set(moving_bodies(model).tolist())
        self._bodies = [paths[b] for b in sorted(moving)]
        for b in range(1, model.nbody):
            if b not in moving:
                pose = rr.Transform3D(translation=data.xpos[b], quaternion=quat(data.xquat[b]))
                rec.log(paths[b], pose, static=True)
        for shape in shapes(model):
            pose = rr.Transform3D(translation=shape.pos, quaternion=quat(shape.quat))
            rec.log(f"{paths[shape.body]}/{shape.name}", pose, archetype(shape), static=True)
        self._styles(task)
        self._tactile_key()

    def _styles(self, task: Sequence[Series]) -> None:
        """Series names and colours: a joint's colour is the same in every finger's plot."""
        rec = self.rec
        for finger, joints, loads in finger_series(self._profile):
            for path, series in ((layout.HAND_JOINTS, joints), (layout.TENDONS, loads)):
                line = rr.SeriesLines(names=series.names, colors=series.colors)
                rec.log(f"{path}/{finger}", line, static=True)
        arm = arm_series(self._profile)
        rec.log(layout.ARM_JOINTS, rr.SeriesLines(names=arm.names, colors=arm.colors), static=True)
        for path, s in zip(self._task, task, strict=True):
            line = rr.SeriesLines(names=[f"{s.label} ({s.unit})"], colors=[TASK_COLOR], widths=2)
            rec.log(path, line, static=True)

    def _tactile_key(self) -> None:
        """The four fingertips, two by two, with their depth scale; the plots' colour key."""
        rec, key = self.rec, layout.KEY
        depth: dict[str, Any] = {"meter": 1000.0, "colormap": "Viridis"}
        depth["depth_range"] = (0.0, TACTILE_MM)
        corners = [[18.0 * (f % 2), 20.0 * (f // 2)] for f in range(len(FINGERS))]
        for (x, y), finger in zip(corners, FINGERS, strict=True):
            path = f"{layout.TACTILE}/{finger}"
            rec.log(path, rr.Transform3D(translation=[x, y, 0.0]), static=True)
            rows, cols = self._profile.hand.taxels
            image = rr.components.ImageFormat(cols, rows, channel_datatype="F32")
            rec.log(path, rr.DepthImage.from_fields(format=image, **depth), static=True)
        rec.log(
            f"{key}/fingers",
            rr.Boxes2D(mins=corners, sizes=[[16, 16]] * 4, colors=[(90, 90, 90)] * 4),
            static=True,
        )
        names = [[x + 8.0, y + 16.3] for x, y in corners]
        rec.log(
            f"{key}/names",
            rr.Points2D(names, radii=0.01, labels=list(FINGERS), show_labels=True),
            static=True,
        )
        x = 35.0
        scale = np.linspace(TACTILE_MM, 0.0, 36, dtype=np.float32).reshape(36, 1)
        rec.log(f"{key}/scale", rr.Transform3D(translation=[x, 0.0, 0.0]), static=True)
        rec.log(f"{key}/scale", rr.DepthImage(scale, **depth), static=True)
        ticks = [[x + 3.0, 0.5], [x + 3.0, 18.0], [x + 3.0, 35.5]]
        labels = [f"{TACTILE_MM:g} mm", f"{TACTILE_MM / 2:g} mm", "0 mm"]
        rec.log(
            f"{key}/ticks",
            rr.Points2D(ticks, radii=0.01, labels=labels, show_labels=True),
            static=True,
        )
        swatches = [
            *zip(JOINTS, JOINT_COLORS, strict=True),
            ("extensor darker", shade((200, 200, 200), EXTENSOR_SHADE)),
            ("guard contact", GUARD_COLOR),
            ("touched point", POINT_COLOR),
        ]
        rec.log(  # a bar of each colour, its name below it
            f"{key}/colours",
            rr.Boxes2D(
                mins=[[44.0, i * 5.0 + 0.3] for i in range(len(swatches))],
                sizes=[[14.0, 0.6]] * len(swatches),
                colors=[c for _, c in swatches],
                labels=[name for name, _ in swatches],
                show_labels=True,
                radii=0.3,
            ),
            static=True,
        )

    # -- over time ----------------------------------------------------------------------------
    def frames(self, batch: Batch) -> None:
        """Send a batch of frames as columns, one call per entity."""
        rec, n = self.rec, len(batch)
        index = [
            rr.TimeColumn("sim_time", duration=batch.time_ns.astype("timedelta64[ns]")),
            rr.TimeColumn("tick", sequence=batch.tick),
        ]

        def scalars(path: str, values: FloatArray) -> None:
            rec.send_columns(path, indexes=index, columns=rr.Scalars.columns(scalars=values))

        for k, path in enumerate(self._bodies):
            poses = rr.Transform3D.columns(translation=batch.pos[:, k], quaternion=batch.quat[:, k])
            rec.send_columns(path, indexes=index, columns=poses)
        per = 2 if self._profile.hand.load == "tendon" else 1  # load readings per joint
        first = 0
        for f, finger in enumerate(FINGERS):
            joints = len(self._profile.fingers[f].joints)
            scalars(f"{layout.HAND_JOINTS}/{finger}", batch.joints[:, 4 * f : 4 * f + joints])
            scalars(f"{layout.TENDONS}/{finger}", batch.tensions[:, first : first + per * joints])
            first += per * joints
            # Rows run proximal to distal: flip them to show the fingertip up. Depths in mm.
            pixels = np.ascontiguousarray(1000.0 * batch.tactile[:, f, ::-1, :], dtype=np.float32)
            rec.send_columns(
                f"{layout.TACTILE}/{finger}",
                indexes=index,
                columns=rr.DepthImage.columns(buffer=pixels.reshape(n, -1).view(np.uint8)),
            )
        scalars(layout.ARM_JOINTS, batch.arm)
        for s, path in enumerate(self._task):
            scalars(path, batch.task[:, s : s + 1])
        self.phases(self.lanes.flush(float(batch.time_ns[-1]) * 1e-9))
        self._send_events()

    def _send_events(self) -> None:
        """The text lines and lane changes gathered since the last batch, as columns."""

        def index(rows: list[Any]) -> list[rr.TimeColumn]:
            ns = np.array([r[0] for r in rows], dtype=np.int64)
            return [
                rr.TimeColumn("sim_time", duration=ns.astype("timedelta64[ns]")),
                rr.TimeColumn("tick", sequence=[r[1] for r in rows]),
            ]

        if self._lines:
            lines, self._lines = self._lines, []
            texts = rr.TextLog.columns(text=[r[2] for r in lines], level=[r[3] for r in lines])
            self.rec.send_columns(layout.LOG, indexes=index(lines), columns=texts)
        changes, self._changes = self._changes, {}
        for path, rows in changes.items():
            states = rr.StateChange.columns(state=[r[2] for r in rows])
            self.rec.send_columns(path, indexes=index(rows), columns=states)

    def record(self, record: Mapping[str, Any], tick: int, tips: FloatArray | None) -> None:
        """One log record at its own simulated time; ``tips`` (4, 3) m locate guard contacts."""
        t, tick = when(record, tick)
        self._at(t, tick)
        described = describe(record)
        if described is not None:
            self.line(t, tick, *described)
        kind = record["kind"]
        if kind == "end":
            self._sensed(record.get("data", {}))
        elif kind == "contact" and tips is not None:
            self._guard(record, tips[FINGERS.index(record["finger"])], t, tick)
        self.phases(self.lanes.feed(record))

    def _at(self, t: float, tick: int) -> None:
        self.rec.set_time("sim_time", duration=np.timedelta64(round(t * 1e9), "ns"))
        self.rec.set_time("tick", sequence=tick)

    def _lane(self, lane: tuple[str, ...]) -> str:
        """The lane's entity path; the first time, its colours (static), which also make
        the lane show in the panel before anything runs on it."""
        path = rr.new_entity_path(list(lane))
        if lane not in self._lanes_seen:
            self._lanes_seen.add(lane)
            colors = [(r << 24) | (g << 16) | (b << 8) | 0xFF for r, g, b in STATE_COLORS.values()]
            config = rr.StateConfiguration(
                values=list(STATE_COLORS), colors=np.array(colors, dtype=np.uint32)
            )
            self.rec.log(path, config, static=True)
        return path

    def open_lanes(self, lanes: Lanes, under: Lane = ()) -> None:
        """One lane per event of the plan (under the path ``under``), empty from time 0,
        also for an event that never runs."""
        self._at(0.0, 0)
        for key in lanes.plan.order:
            self.rec.log(self._lane((*under, *lanes.path(key))), rr.StateChange.cleared())

    def phases(self, phases: list[Phase], under: Lane = ()) -> None:
        """Lane changes, each at its own time, under the path ``under``; a lane's first
        change brings its colours."""
        for phase in phases:
            path = self._lane((*under, *phase.lane))
            self._at(phase.t, phase.tick)
            state = (
                rr.StateChange.cleared()
                if phase.state is None
                else rr.StateChange(state=phase.state)
            )
            self.rec.log(path, state)

    def _guard(self, record: Mapping[str, Any], tip: FloatArray, t: float, tick: int) -> None:
        """A guard's contact at the sensing fingertip, labelled, shown for GUARD_SHOWN_S."""
        self._guards += 1
        path = f"world/contacts/guards/{self._guards:02d}"
        unit = "N" if record["sensor"] == "force" else "m"
        label = f"{record['finger']} {record['sensor']} {record['value']:.3g} {unit}"
        self.rec.log(path, rr.Points3D([tip], radii=0.006, colors=GUARD_COLOR, labels=[label]))
        self._at(t + GUARD_SHOWN_S, tick)
        self.rec.log(path, rr.Clear(recursive=False))
        self._at(t, tick)

    def _sensed(self, data: Mapping[str, Any]) -> None:
        """Contact points and fits carried by an ``end`` record's data."""
        name = str(data.get("set", "points"))
        if "point" in data:
            points = self._points.setdefault(name, [])
            points.append(np.asarray(data["point"]))
            self.rec.log(
                f"world/contacts/{name}",
                rr.Points3D(points, radii=0.004, colors=POINT_COLOR, labels=[name] * len(points)),
            )
        elif "normal" in data:
            axes = np.asarray(data["axes"])
            rot = np.stack([axes[0], axes[1], np.asarray(data["normal"])], axis=1)
            extents = np.asarray(data["extents"]) / 2.0
            self.rec.log(
                f"world/fits/{name}",
                rr.Transform3D(translation=data["centroid"], mat3x3=rot),
                rr.Boxes3D(
                    half_sizes=[[extents[0], extents[1], PLANE_THICKNESS / 2]],
                    colors=FIT_COLOR,
                    fill_mode=SOLID,
                ),
            )
        elif "shape" in data:
            vertices, faces = superquadric_mesh(np.asarray(data["size"]), np.asarray(data["shape"]))
            self.rec.log(
                f"world/fits/{name}",
                rr.Transform3D(translation=data["centre"], mat3x3=np.asarray(data["rotation"])),
                rr.Mesh3D(
                    vertex_positions=vertices, triangle_indices=faces, albedo_factor=FIT_COLOR
                ),
            )

    # -- a second robot: a remote run's reported one, beside the predicted (docs/remote.md) --
    def ghost(self, model: mujoco.MjModel, paths: Mapping[int, str], color: FloatArray) -> None:
        """The geometry of the bodies in ``paths`` again, under those entity paths, all in
        ``color`` (RGBA, 0-1)."""
        for shape in shapes(model):
            if shape.body in paths:
                pose = rr.Transform3D(translation=shape.pos, quaternion=quat(shape.quat))
                drawn = archetype(dataclasses.replace(shape, rgba=color))
                self.rec.log(f"{paths[shape.body]}/{shape.name}", pose, drawn, static=True)

    def poses(self, t: float, tick: int, paths: Mapping[int, str], data: mujoco.MjData) -> None:
        """Those bodies' poses at simulated time ``t`` and ``tick``."""
        self._at(t, tick)
        for b, path in paths.items():
            pose = rr.Transform3D(translation=data.xpos[b], quaternion=quat(data.xquat[b]))
            self.rec.log(path, pose)

    def line(self, t: float, tick: int, text: str, level: str) -> None:
        """A line of the text log (level: info, warn, error), sent with the next batch."""
        self._lines.append((round(t * 1e9), tick, text, LEVELS[level]))

    def close(self) -> None:
        self.phases(self.lanes.flush())
        self._send_events()
        # A viewer closed mid-run must not keep the run from ending.
        self.rec.flush(timeout_sec=FLUSH_TIMEOUT_S if self.live else 1e38)
        self.rec.disconnect()
