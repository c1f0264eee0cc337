"""``dial replay LOG --record OUT.rrd --video OUT.mp4``: a recording or a video rebuilt from
a log's ``state`` records.

A state (written with ``dial run --log FILE --log-states``) holds the whole ``qpos`` and the
32 tendon tensions. Positions give everything else: body poses by forward kinematics, and
the tactile images, which are penetration depths. The scene comes from the log's ``scene``
record (its name, and the perturbation of the fixed objects; free objects are in ``qpos``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from dial.backend.model import load_model, profile_at
from dial.errors import DialError
from dial.recording.geometry import task_camera
from dial.recording.lanes import LanePlan
from dial.recording.observers import object_bodies, open_scene
from dial.recording.rerun_sink import RerunSink
from dial.recording.video import VIDEO_FPS, Renderer, VideoFile
from dial.scene.resolve import resolve_scene
from dial.scene.world import World, load_world


def _replayed(
    records: Sequence[dict[str, Any]], base: Path, what: str
) -> tuple[World, mujoco.MjModel, mujoco.MjData, list[dict[str, Any]]]:
    """The log's scene as it was during the run, at its first state, and its states."""
    states = [r for r in records if r["kind"] == "state"]
    if not states:
        raise DialError(
            f"the log holds no 'state' records to rebuild {what} from; "
            "run the script with --log FILE.jsonl --log-states"
        )
    scene = records[0]
    path = Path(str(scene.get("world", "")))
    # A world that is not bundled is logged by its absolute path.
    world = load_world(
        path if path.is_absolute() and path.is_file() else resolve_scene(str(scene["scene"]), base)
    )
    model = load_model(world.model_path, profile_at(world.robot))
    data = mujoco.MjData(model)
    for name in world.objects.values():  # --perturb moved the fixed objects in the model
        body = model.body(name).id
        if model.body_parentid[body] == 0 and model.body_jntnum[body] == 0:
            model.body_pos[body] += scene.get("perturb", [0.0, 0.0, 0.0])
    if len(states[0]["qpos"]) != model.nq:
        raise DialError(
            f"the log's states hold {len(states[0]['qpos'])} positions, but scene "
            f"'{world.name}' has {model.nq}: it has changed since the run"
        )
    data.qpos[:] = states[0]["qpos"]
    mujoco.mj_forward(model, data)
    return world, model, data, states


def rebuild(records: Sequence[dict[str, Any]], out: Path, title: str, base: Path) -> int:
    """Write the run in ``records`` as a recording to ``out``; returns the number of frames.

    ``base`` is where a scene given as a relative path resolves (the log's directory).
    """
    world, model, data, states = _replayed(records, base, "a recording")
    sink = RerunSink(out)
    try:
        _send(records, model, data, sink, title, world)
    finally:
        sink.close()
    return len(states)


def render_video(records: Sequence[dict[str, Any]], out: Path, base: Path) -> int:
    """Render the log's states as a video to ``out`` (.mp4 or .gif), one frame per state,
    from the camera of ``dial run --video``; returns the number of frames."""
    world, model, data, states = _replayed(records, base, "a video")
    times = [float(r["t"]) for r in states]
    step = float(np.median(np.diff(times))) if len(times) > 1 else 1.0 / VIDEO_FPS
    camera = task_camera(data, object_bodies(model, list(world.objects.values())))
    renderer = Renderer(model, camera)
    try:
        writer = VideoFile(out, 1.0 / step)
        try:
            for state in states:
                data.qpos[:] = state["qpos"]
                mujoco.mj_forward(model, data)
                writer.write(renderer.render(data))
        finally:
            writer.close()
    finally:
        renderer.close()
    return len(states)


def _send(
    records: Sequence[dict[str, Any]],
    model: mujoco.MjModel,
    data: mujoco.MjData,
    sink: RerunSink,
    title: str,
    world: World,
) -> None:
    plan = next((LanePlan.from_record(r) for r in records if r["kind"] == "lanes"), None)
    frames = open_scene(sink, model, data, world, title, plan)
    tips = frames.index.fingertip_sites
    tick = 0
    for record in records:
        if record["kind"] != "state":
            sink.record(record, tick, data.site_xpos[tips])
            continue
        tick = int(record["tick"])
        data.qpos[:] = record["qpos"]
        mujoco.mj_forward(model, data)
        frames.capture(float(record["t"]), tick, data, np.asarray(record["tension"]))
        if len(frames) >= sink.batch:
            batch = frames.take()
            assert batch is not None
            sink.frames(batch)
    batch = frames.take()
    if batch is not None:
        sink.frames(batch)
