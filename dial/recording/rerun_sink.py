"""Every rerun call in dial: a run as a ``.rrd`` recording or a live stream to a viewer.

Layout (entity paths):

- ``world``: the scene, z up. ``world/<body>`` holds a body's pose in the world frame (static
  for bodies welded to the world, over time for the rest); ``world/<body>/<geom>`` its shapes.
  ``world/contacts/<set>`` the recorded contact points, ``world/contacts/guards`` where a
  guard stopped an effector (at the sensing fingertip), ``world/fits/<set>`` fitted planes
  and superquadrics.
- ``robot/joints/<finger>`` four joint angles (rad), ``robot/tendons/<finger>`` eight tendon
  tensions (N).
- ``tactile/<finger>``: the 16x16 depths (m), fingertip up, seen from the object.
- ``events/log``: a text log of starts, ends, contacts, warnings and the criteria;
  ``events/lanes/<event>``: ``running`` while a run of the event executes (a called script's
  events: ``events/lanes/<script stem>.<event>``).

Two timelines: ``sim_time`` (simulated time) and ``tick`` (the absolute tick).
Body poses, joints, tensions and tactile images are sent as columns in batches of frames:
one call per entity per batch keeps the cost per frame to an array copy.
"""

from __future__ import annotations

import socket
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from dial.backend.model import FINGERS
from dial.backend.snapshot import FloatArray
from dial.errors import DialError
from dial.recording.frames import Batch
from dial.recording.geometry import (
    Camera,
    Shape,
    body_names,
    moving_bodies,
    shapes,
    superquadric_mesh,
)
from dial.recording.timeline import describe, qualified_event, when

APP_ID = "dial"
TACTILE_RANGE = (0.0, 1e-3)  # m; a firm press is 0.5-1 mm deep
JOINTS = ("abd", "mcp", "pip", "dip")
LEVELS = {
    "info": rr.TextLogLevel.INFO,
    "warn": rr.TextLogLevel.WARN,
    "error": rr.TextLogLevel.ERROR,
}
SOLID = rr.components.FillMode.Solid
PLANE_THICKNESS = 1e-3  # m, to draw a fitted plane as a thin box
VIEWER_PORT = 9876  # rerun's default
FLUSH_TIMEOUT_S = 10.0


def blueprint(camera: Camera | None) -> rrb.Blueprint:
    """The scene and event lanes on the left; tactile, joints, tendons and the log on the right."""
    eye = None
    if camera is not None:
        eye = rrb.EyeControls3D(
            position=camera.position(), look_target=camera.lookat, eye_up=(0.0, 0.0, 1.0)
        )
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(
                rrb.Spatial3DView(origin="world", name="scene", eye_controls=eye),
                rrb.StateTimelineView(origin="events/lanes", name="events"),
                row_shares=[3, 1],
            ),
            rrb.Vertical(
                rrb.Horizontal(
                    *(
                        rrb.Spatial2DView(origin=f"tactile/{f}", name=f"{f} tactile")
                        for f in FINGERS
                    )
                ),
                rrb.TimeSeriesView(origin="robot/joints", name="joint angles (rad)"),
                rrb.TimeSeriesView(origin="robot/tendons", name="tendon tensions (N)"),
                rrb.TextLogView(origin="events/log", name="log"),
            ),
            column_shares=[3, 2],
        ),
        collapse_panels=True,
    )


def _listening(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), timeout=1.0).close()
    except OSError:
        return False
    return True


def _rgba(rgba: FloatArray) -> np.ndarray:
    return np.asarray(np.round(np.clip(rgba, 0.0, 1.0) * 255), dtype=np.uint8)


def _quat(wxyz: FloatArray) -> rr.Quaternion:
    """MuJoCo's (w, x, y, z) as rerun's quaternion, stored (x, y, z, w)."""
    return rr.Quaternion(xyzw=[wxyz[1], wxyz[2], wxyz[3], wxyz[0]])


def _archetype(shape: Shape) -> Any:
    color = _rgba(shape.rgba)
    r, half = float(shape.size[0]), float(shape.size[1])
    if shape.kind == "box":
        return rr.Boxes3D(half_sizes=[shape.size], colors=color, fill_mode=SOLID)
    if shape.kind in ("sphere", "ellipsoid"):
        size = [r, r, r] if shape.kind == "sphere" else shape.size
        return rr.Ellipsoids3D(half_sizes=[size], colors=color, fill_mode=SOLID)
    if shape.kind == "capsule":  # rerun's capsule starts at the origin; MuJoCo's is centred
        return rr.Capsules3D(
            lengths=[2 * half], radii=[r], translations=[[0.0, 0.0, -half]], colors=color
        )
    if shape.kind == "cylinder":
        return rr.Cylinders3D(lengths=[2 * half], radii=[r], colors=color, fill_mode=SOLID)
    assert shape.vertices is not None and shape.faces is not None
    return rr.Mesh3D(
        vertex_positions=shape.vertices, triangle_indices=shape.faces, albedo_factor=color
    )


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
        self._bodies: list[str] = []
        self._points: dict[str, list[FloatArray]] = {}

    # -- once ---------------------------------------------------------------------------------
    def scene(
        self, model: mujoco.MjModel, data: mujoco.MjData, title: str, camera: Camera | None
    ) -> None:
        """Static geometry and the blueprint; ``data`` gives the poses of fixed bodies."""
        rec = self.rec
        rec.send_recording_name(title)
        rec.send_blueprint(blueprint(camera))
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        names = body_names(model)
        names[0] = "static"  # the world body's own geoms: the PUMA's pedestal
        moving = set(moving_bodies(model).tolist())
        self._bodies = [f"world/{names[b]}" for b in sorted(moving)]
        for b in range(1, model.nbody):
            if b not in moving:
                pose = rr.Transform3D(translation=data.xpos[b], quaternion=_quat(data.xquat[b]))
                rec.log(f"world/{names[b]}", pose, static=True)
        for shape in shapes(model):
            pose = rr.Transform3D(translation=shape.pos, quaternion=_quat(shape.quat))
            rec.log(f"world/{names[shape.body]}/{shape.name}", pose, _archetype(shape), static=True)
        for finger in FINGERS:
            names4 = [f"{finger} {j}" for j in JOINTS]
            rec.log(f"robot/joints/{finger}", rr.SeriesLines(names=names4), static=True)
            tendons = [f"{n} {k}" for n in names4 for k in ("flexor", "extensor")]
            rec.log(f"robot/tendons/{finger}", rr.SeriesLines(names=tendons), static=True)
            depth = rr.DepthImage.from_fields(
                format=rr.components.ImageFormat(16, 16, channel_datatype="F32"),
                meter=1.0,
                colormap="Viridis",
                depth_range=TACTILE_RANGE,
            )
            rec.log(f"tactile/{finger}", depth, static=True)

    # -- over time ----------------------------------------------------------------------------
    def frames(self, batch: Batch) -> None:
        """Send a batch of frames as columns, one call per entity."""
        rec, n = self.rec, len(batch)
        index = [
            rr.TimeColumn("sim_time", duration=batch.time_ns.astype("timedelta64[ns]")),
            rr.TimeColumn("tick", sequence=batch.tick),
        ]
        for k, path in enumerate(self._bodies):
            poses = rr.Transform3D.columns(translation=batch.pos[:, k], quaternion=batch.quat[:, k])
            rec.send_columns(path, indexes=index, columns=poses)
        for f, finger in enumerate(FINGERS):
            joints = batch.joints[:, 4 * f : 4 * f + 4]
            tensions = batch.tensions[:, 8 * f : 8 * f + 8]
            rec.send_columns(
                f"robot/joints/{finger}", indexes=index, columns=rr.Scalars.columns(scalars=joints)
            )
            rec.send_columns(
                f"robot/tendons/{finger}",
                indexes=index,
                columns=rr.Scalars.columns(scalars=tensions),
            )
            # Rows run proximal to distal: flip them to show the fingertip up.
            pixels = np.ascontiguousarray(batch.tactile[:, f, ::-1, :], dtype=np.float32)
            rec.send_columns(
                f"tactile/{finger}",
                indexes=index,
                columns=rr.DepthImage.columns(buffer=pixels.reshape(n, -1).view(np.uint8)),
            )

    def record(self, record: Mapping[str, Any], tick: int, tips: FloatArray | None) -> None:
        """One log record at its own simulated time; ``tips`` (4, 3) m locate guard contacts."""
        rec = self.rec
        t, tick = when(record, tick)
        rec.set_time("sim_time", duration=np.timedelta64(round(t * 1e9), "ns"))
        rec.set_time("tick", sequence=tick)
        described = describe(record)
        if described is not None:
            text, level = described
            rec.log("events/log", rr.TextLog(text, level=LEVELS[level]))
        kind = record["kind"]
        if kind == "start":
            rec.log(f"events/lanes/{qualified_event(record)}", rr.StateChange(state="running"))
        elif kind == "end":
            rec.log(f"events/lanes/{qualified_event(record)}", rr.StateChange.cleared())
            self._sensed(record.get("data", {}))
        elif kind == "contact" and tips is not None:
            self._point("guards", tips[FINGERS.index(record["finger"])], (255, 80, 40))

    def _sensed(self, data: Mapping[str, Any]) -> None:
        """Contact points and fits carried by an ``end`` record's data."""
        name = str(data.get("set", "points"))
        if "point" in data:
            self._point(name, np.asarray(data["point"]), (40, 160, 255))
        elif "normal" in data:
            axes = np.asarray(data["axes"])
            rot = np.stack([axes[0], axes[1], np.asarray(data["normal"])], axis=1)
            extents = np.asarray(data["extents"]) / 2.0
            self.rec.log(
                f"world/fits/{name}",
                rr.Transform3D(translation=data["centroid"], mat3x3=rot),
                rr.Boxes3D(
                    half_sizes=[[extents[0], extents[1], PLANE_THICKNESS / 2]],
                    colors=(255, 200, 0, 140),
                    fill_mode=SOLID,
                ),
            )
        elif "shape" in data:
            vertices, faces = superquadric_mesh(np.asarray(data["size"]), np.asarray(data["shape"]))
            self.rec.log(
                f"world/fits/{name}",
                rr.Transform3D(translation=data["centre"], mat3x3=np.asarray(data["rotation"])),
                rr.Mesh3D(
                    vertex_positions=vertices,
                    triangle_indices=faces,
                    albedo_factor=(255, 200, 0, 140),
                ),
            )

    def _point(self, name: str, point: FloatArray, color: tuple[int, int, int]) -> None:
        points = self._points.setdefault(name, [])
        points.append(point)
        self.rec.log(f"world/contacts/{name}", rr.Points3D(points, radii=0.004, colors=color))

    def close(self) -> None:
        # A viewer closed mid-run must not keep the run from ending.
        self.rec.flush(timeout_sec=FLUSH_TIMEOUT_S if self.live else 1e38)
        self.rec.disconnect()
