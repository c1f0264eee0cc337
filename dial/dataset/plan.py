"""What a run or a sweep asks of a dataset (fps, cameras, successful runs only), and the
features its episodes will have, known before anything runs."""

from __future__ import annotations

import importlib.util
import os
import sys
from dataclasses import dataclass

from dial.dataset.features import DEFAULT_FPS, FeatureJSON, check_fps
from dial.errors import OptionError
from dial.scene.world import World

CAMERA_SIZE = (240, 320)  # height, width of every camera's frames


@dataclass(frozen=True)
class Request:
    """``--fps``, ``--cameras`` and ``--successful-only``: small, so a trial carries it."""

    fps: int = DEFAULT_FPS
    cameras: tuple[str, ...] = ()
    successful_only: bool = False


def check_request(request: Request) -> None:
    """A usage error (:class:`OptionError`) for a bad ``--fps`` or a missing extra."""
    check_fps(request.fps)
    if importlib.util.find_spec("pyarrow") is None:
        raise OptionError("--dataset needs pyarrow: pip install 'dial[dataset]'")
    if request.cameras and not all(
        importlib.util.find_spec(m) is not None for m in ("imageio", "imageio_ffmpeg")
    ):
        raise OptionError("--cameras needs the optional 'video' extra: pip install 'dial[video]'")
    if request.cameras and sys.platform.startswith("linux"):  # offscreen, before MuJoCo loads
        os.environ.setdefault("MUJOCO_GL", "egl")


def expected_features(world: World, request: Request) -> dict[str, FeatureJSON]:
    """The data features of a run in ``world`` (MuJoCo loads: the robot's names live with
    its model)."""
    from dial.backend.model import profile_at
    from dial.dataset.features import features
    from dial.dataset.robot import robot_names, scene_bodies

    bodies = scene_bodies(list(world.objects.values()))
    if request.cameras:
        check_cameras(world, request.cameras)
    cameras = dict.fromkeys(request.cameras, CAMERA_SIZE)
    spec = features(robot_names(profile_at(world.robot)), bodies, cameras, request.fps)
    return {name: feature.as_json() for name, feature in spec.items()}


def check_cameras(world: World, names: tuple[str, ...]) -> None:
    """A usage error for a camera the scene's model lacks (its model is compiled for it)."""
    import mujoco

    from dial.backend.model import load_model, profile_at

    model = load_model(world.model_path, profile_at(world.robot))
    known = [
        "task",
        *(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(model.ncam)),
    ]
    unknown = [n for n in names if n not in known]
    if unknown:
        raise OptionError(
            f"--cameras: the scene {world.name} has no camera '{unknown[0]}' "
            f"(it has: {', '.join(n for n in known if n)})"
        )
