"""What a dataset's frames hold: each feature's dtype, shape and per-dimension names.

The feature set is a pure function of the robot's part names and the scene's objects, so a
run can be checked against an existing dataset before it starts. It is written to
``meta/info.json`` as LeRobot's ``features`` (docs/datasets.md lists every dimension).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from dial.errors import OptionError

FeatureJSON = dict[str, object]  # one feature as info.json holds it
DEFAULT_FPS = 50
MAX_FPS = 100  # frames are resampled from the 100 Hz control periods


def check_fps(fps: int) -> None:
    """A usage error (:class:`OptionError`) unless ``fps`` is a whole number in range."""
    if isinstance(fps, bool) or not isinstance(fps, int) or not 1 <= fps <= MAX_FPS:
        raise OptionError(f"--fps must be a whole number from 1 to {MAX_FPS}, got {fps}")


# The columns LeRobot's reader requires of every frame, after the features of the data.
INDEX_FEATURES: tuple[tuple[str, str], ...] = (
    ("timestamp", "float32"),
    ("frame_index", "int64"),
    ("episode_index", "int64"),
    ("index", "int64"),
    ("task_index", "int64"),
)
POSE = ("x", "y", "z", "qw", "qx", "qy", "qz")  # an object's position (m) and unit quaternion
CAMERA_AXES = ("height", "width", "channels")
VIDEO_PREFIX = "observation.images."


@dataclass(frozen=True)
class RobotNames:
    """What the features of a robot are named after (:func:`dial.dataset.robot.robot_names`)."""

    arm_joints: tuple[str, ...]
    hand_joints: tuple[str, ...]  # mask order
    load: tuple[str, ...]  # one per joint-load reading
    fingers: tuple[str, ...]
    taxels: tuple[int, int]  # rows, columns of a fingertip's tactile array
    robot_type: str = "utah_hand_puma"


@dataclass(frozen=True)
class Feature:
    """One feature: ``dtype`` (a numpy dtype name, or "video"), ``shape`` per frame, and
    ``names``: one per element of a vector, or one per axis of an array."""

    dtype: str
    shape: tuple[int, ...]
    names: tuple[str, ...] | None
    info: Mapping[str, object] | None = None  # a video's codec, size and fps

    def as_json(self) -> FeatureJSON:
        out: FeatureJSON = {
            "dtype": self.dtype,
            "shape": list(self.shape),
            "names": None if self.names is None else list(self.names),
        }
        if self.info is not None:
            out["info"] = dict(self.info)
        return out


Features = dict[str, Feature]


def features(
    robot: RobotNames,
    bodies: Sequence[str],
    cameras: Mapping[str, tuple[int, int]] | None = None,
    fps: int = 50,
) -> Features:
    """The data features of a run of ``robot`` among ``bodies``, with ``cameras`` (name ->
    (height, width)) as videos at ``fps``; the index columns are not among them."""
    joints = robot.arm_joints + robot.hand_joints
    out: Features = {
        "action": Feature("float32", (len(joints),), joints),
        "observation.state": Feature("float32", (len(joints),), joints),
        "observation.velocity": Feature("float32", (len(joints),), joints),
        "observation.joint_load": Feature("float32", (len(robot.load),), robot.load),
        "observation.tactile": Feature(
            "float32", (len(robot.fingers), *robot.taxels), ("finger", "row", "col")
        ),
        "observation.environment_state": Feature(
            "float32", (len(POSE) * len(bodies),), tuple(f"{b}_{p}" for b in bodies for p in POSE)
        ),
    }
    for name, (height, width) in (cameras or {}).items():
        out[VIDEO_PREFIX + name] = Feature(
            "video", (height, width, 3), CAMERA_AXES, video_info(fps)
        )
    out["next.done"] = Feature("bool", (1,), None)
    out["next.success"] = Feature("bool", (1,), None)
    return out


def shape_of(feature: Mapping[str, object]) -> tuple[int, ...]:
    """A feature's ``shape`` as a tuple of ints (info.json holds a list)."""
    shape = feature.get("shape")
    if not isinstance(shape, list | tuple) or not all(isinstance(n, int) for n in shape):
        raise ValueError(f"a feature's shape must be a list of whole numbers, not {shape!r}")
    return tuple(int(n) for n in shape)


def video_info(fps: int) -> dict[str, object]:
    """What info.json says of a camera's video (as LeRobot's writer puts it)."""
    return {
        "video.fps": fps,
        "video.codec": "h264",
        "video.pix_fmt": "yuv420p",
        "video.is_depth_map": False,
        "has_audio": False,
    }


def all_features(data: Mapping[str, FeatureJSON]) -> dict[str, FeatureJSON]:
    """info.json's ``features``: the data features, then the index columns."""
    out = dict(data)
    for name, dtype in INDEX_FEATURES:
        out[name] = {"dtype": dtype, "shape": [1], "names": None}
    return out


def difference(have: Mapping[str, object], want: Mapping[str, object]) -> str | None:
    """The first difference between two info.json ``features``, in words; None if equal."""
    missing = [name for name in have if name not in want]
    extra = [name for name in want if name not in have]
    if missing:
        return f"'{missing[0]}' is in the dataset but not in this run's features"
    if extra:
        return f"'{extra[0]}' is in this run's features but not in the dataset"
    for name in have:
        a, b = have[name], want[name]
        if a == b or not (isinstance(a, Mapping) and isinstance(b, Mapping)):
            continue
        for key in ("dtype", "names", "shape", "info"):
            x, y = a.get(key), b.get(key)
            if x == y:
                continue
            if isinstance(x, list) and isinstance(y, list):
                i = next(
                    (i for i, (u, v) in enumerate(zip(x, y, strict=False)) if u != v),
                    min(len(x), len(y)),
                )
                u = x[i] if i < len(x) else "(none)"
                v = y[i] if i < len(y) else "(none)"
                return f"'{name}' {key}[{i}] is {u} in the dataset, {v} in this run"
            return f"'{name}' has {key} {x} in the dataset, {y} in this run"
    return None
