"""What a recording draws, read from the MuJoCo model: bodies and their visible geoms.

Pure MuJoCo and numpy; the rerun calls live in :mod:`dial.recording.rerun_sink`.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, replace

import mujoco
import numpy as np

from dial.robot.snapshot import FloatArray
from dial.robots.profile import RobotProfile

SHOWN_GROUPS = 4  # geom groups 0-3 are drawn; 4 and up hold debug sites and markers
KINDS = {
    mujoco.mjtGeom.mjGEOM_SPHERE: "sphere",
    mujoco.mjtGeom.mjGEOM_CAPSULE: "capsule",
    mujoco.mjtGeom.mjGEOM_ELLIPSOID: "ellipsoid",
    mujoco.mjtGeom.mjGEOM_CYLINDER: "cylinder",
    mujoco.mjtGeom.mjGEOM_BOX: "box",
    mujoco.mjtGeom.mjGEOM_MESH: "mesh",
}  # planes (the floor) are left to the viewer's ground grid


TASK_AZIMUTH, TASK_ELEVATION = 165.0, -18.0  # deg: from the front, a little from the side
WORKSPACE_ABOVE = 0.3  # m above the objects that the hand works in
EYE_AZIMUTH, EYE_ELEVATION = 135.0, -25.0  # deg: more from the side and from above, so
# that the hand shows beside the objects it works on, and into cups


@dataclass(frozen=True)
class Camera:
    """A fixed camera in MuJoCo's free-camera terms: ``lookat`` (3,) m, ``distance`` m,
    ``azimuth`` and ``elevation`` deg (negative looks down)."""

    lookat: tuple[float, float, float]
    distance: float
    azimuth: float
    elevation: float

    def position(self) -> tuple[float, float, float]:
        """Where the camera sits, in the world frame (m)."""
        az, el = np.radians(self.azimuth), np.radians(self.elevation)
        forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        x, y, z = np.asarray(self.lookat) - self.distance * forward
        return (float(x), float(y), float(z))


def task_camera(data: mujoco.MjData, objects: list[int]) -> Camera:
    """A camera on the task: the table's front edge below, the objects in the middle, the arm
    behind them on the left, slightly from the side so that a pour or a twist shows.

    It looks at a point 0.2 m above the objects' centroid, a little towards the arm's base
    (the world origin), so that the hand stays in view as it works on them.
    """
    centre = data.xpos[objects].mean(axis=0) if objects else np.array([0.5, 0.0, 0.35])
    lookat = (0.9 * float(centre[0]), float(centre[1]), float(centre[2]) + 0.2)
    return Camera(lookat, distance=1.1, azimuth=TASK_AZIMUTH, elevation=TASK_ELEVATION)


def workspace_eye(
    data: mujoco.MjData, objects: list[int], fov_deg: float = 75.0
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """A viewer's eye on the task's workspace: the objects, and the hand as it works on
    them. ``(position, look_target)`` in m: from the task camera's direction, looking at a
    point above the objects, near enough that the workspace fills the vertical field of view
    ``fov_deg``."""
    points = data.xpos[objects] if objects else np.array([[0.5, 0.0, 0.35]])
    low, high = points.min(axis=0), points.max(axis=0)
    target = (low + high) / 2.0 + np.array([0.0, 0.0, WORKSPACE_ABOVE / 2.0])
    radius = float(np.linalg.norm(high - low)) / 2.0 + WORKSPACE_ABOVE
    distance = radius / np.tan(np.radians(fov_deg) / 2.0)
    az, el = np.radians(EYE_AZIMUTH), np.radians(EYE_ELEVATION)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    eye = target - distance * forward
    return (
        (float(eye[0]), float(eye[1]), float(eye[2])),
        (float(target[0]), float(target[1]), float(target[2])),
    )


@dataclass(frozen=True, eq=False)
class Shape:
    """One visible geom, in its body's frame.

    ``size`` is MuJoCo's geom size (3,) m; ``pos`` (3,) m and ``quat`` (4,) (w, x, y, z) place
    it in the body; ``rgba`` (4,) in [0, 1]. Meshes carry ``vertices`` (V, 3) m in the geom
    frame and ``faces`` (F, 3) vertex indices.
    """

    body: int
    name: str
    kind: str
    size: FloatArray
    pos: FloatArray
    quat: FloatArray
    rgba: FloatArray
    vertices: FloatArray | None = None
    faces: np.ndarray | None = None


def entity_names(model: mujoco.MjModel, obj: mujoco.mjtObj, count: int, prefix: str) -> list[str]:
    """Names usable as entity path parts: the model's name, or ``prefix<id>`` when unnamed."""
    names = []
    for i in range(count):
        name = mujoco.mj_id2name(model, obj, i) or f"{prefix}{i}"
        names.append(re.sub(r"[^A-Za-z0-9_.-]", "_", name))
    return names


def body_names(model: mujoco.MjModel) -> list[str]:
    return entity_names(model, mujoco.mjtObj.mjOBJ_BODY, model.nbody, "body")


Groups = tuple[tuple[str, str], ...]  # body-name prefix -> entity group
GROUPS: Groups = (("puma_", "arm/"), ("hand_", "hand/"))  # the first robot's


def name_groups(robot: RobotProfile) -> Groups:
    """A robot's groups, from the prefixes of its arm's and its hand's first joint names: the
    word before the first ``_`` (``puma_``, ``hand_``; ``panda_``, ``allegro_``); none for a
    name without one."""
    groups = []
    first = (robot.arm.joints[0], robot.fingers[0].joints[0])
    for name, group in zip(first, ("arm/", "hand/"), strict=True):
        head, sep, _ = name.partition("_")
        if sep:
            groups.append((head + sep, group))
    return tuple(groups)


def body_paths(
    model: mujoco.MjModel, objects: Mapping[str, str], robot: RobotProfile | None = None
) -> list[str]:
    """Each body's entity path under ``world``, readable on hover: ``arm/link2``,
    ``hand/index_distal`` (the robot's bodies, by its :func:`name_groups`; the first robot's
    when None), a scene object by its alias (``bulb``; ``objects`` maps aliases to body
    names), ``scene/<body>`` for the rest, and ``scene/static`` for the world body."""
    groups = GROUPS if robot is None else name_groups(robot)
    alias = {body: name for name, body in objects.items()}
    paths = []
    for i, name in enumerate(body_names(model)):
        group = next((g + name[len(p) :] for p, g in groups if name.startswith(p)), None)
        paths.append("scene/static" if i == 0 else alias.get(name) or group or f"scene/{name}")
    return paths


def geom_labels(model: mujoco.MjModel, geoms: list[int], kinds: list[str]) -> list[str]:
    """Entity path parts for ``geoms`` (of ``kinds``): a geom's own name less the words it
    shares with its body's (``hand_index_pad`` on ``hand_index_distal``: ``pad``), else its
    kind; numbered when a body has several (``capsule``, ``box_2``)."""
    names = entity_names(model, mujoco.mjtObj.mjOBJ_GEOM, model.ngeom, "")
    bodies = body_names(model)
    labels: list[str] = []
    seen: set[tuple[str, str]] = set()
    for g, kind in zip(geoms, kinds, strict=True):
        body = bodies[int(model.geom_bodyid[g])]
        words, shared = names[g].split("_"), body.split("_")
        n = 0
        while n < min(len(words) - 1, len(shared)) and words[n] == shared[n]:
            n += 1
        named = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g)
        name = "_".join(words[n:]) if named else kind
        label, count = name, 1
        while (body, label) in seen:
            count += 1
            label = f"{name}_{count}"
        seen.add((body, label))
        labels.append(label)
    return labels


def moving_bodies(model: mujoco.MjModel) -> np.ndarray:
    """Ids of the bodies that can move: those not welded to the world (the arm, hand, objects)."""
    return np.flatnonzero(model.body_weldid != 0)


def shapes(model: mujoco.MjModel) -> list[Shape]:
    """Every geom in groups 0-3 with a drawable type and a visible colour, in geom order."""
    out = []
    drawn = []
    for g in range(model.ngeom):
        kind = KINDS.get(mujoco.mjtGeom(int(model.geom_type[g])))
        mat = int(model.geom_matid[g])
        rgba = model.mat_rgba[mat] if mat >= 0 else model.geom_rgba[g]
        if kind is None or model.geom_group[g] >= SHOWN_GROUPS or rgba[3] <= 0.0:
            continue
        vertices = faces = None
        if kind == "mesh":
            mesh = int(model.geom_dataid[g])
            v0, nv = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
            f0, nf = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
            vertices = model.mesh_vert[v0 : v0 + nv].astype(np.float64)
            faces = model.mesh_face[f0 : f0 + nf].copy()
        drawn.append(g)
        out.append(
            Shape(
                body=int(model.geom_bodyid[g]),
                name="",
                kind=kind,
                size=model.geom_size[g].copy(),
                pos=model.geom_pos[g].copy(),
                quat=model.geom_quat[g].copy(),
                rgba=np.asarray(rgba, dtype=np.float64).copy(),
                vertices=vertices,
                faces=faces,
            )
        )
    labels = geom_labels(model, drawn, [s.kind for s in out])
    return [replace(s, name=label) for s, label in zip(out, labels, strict=True)]


def superquadric_mesh(
    size: FloatArray, shape: FloatArray, n: int = 24
) -> tuple[FloatArray, np.ndarray]:
    """A superquadric's surface in its own frame: vertices (V, 3) m and faces (F, 3).

    ``size`` (3,) half-sizes, ``shape`` (eps1, eps2) as in :mod:`dial.haptics.fit`.
    """

    def power(x: FloatArray, e: float) -> FloatArray:
        return np.asarray(np.sign(x) * np.abs(x) ** e)

    eta = np.linspace(-np.pi / 2, np.pi / 2, n + 1)[:, None]  # latitude, rows
    omega = np.linspace(-np.pi, np.pi, 2 * n + 1)[None, :]  # longitude, columns
    e1, e2 = float(shape[0]), float(shape[1])
    x = size[0] * power(np.cos(eta), e1) * power(np.cos(omega), e2)
    y = size[1] * power(np.cos(eta), e1) * power(np.sin(omega), e2)
    z = size[2] * power(np.sin(eta), e1) * np.ones_like(omega)
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    cols = 2 * n + 1
    r, c = np.meshgrid(np.arange(n), np.arange(2 * n), indexing="ij")
    a = (r * cols + c).ravel()
    b, d, e = a + 1, a + cols, a + cols + 1
    faces = np.concatenate([np.stack([a, b, e], 1), np.stack([a, e, d], 1)])
    return vertices, faces
