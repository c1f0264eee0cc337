"""Load dial's exports with LeRobot's own ``LeRobotDataset``, offline, and compare.

Run by ``test_lerobot.py`` with the Python of an environment that has ``lerobot[dataset]``
(it needs Python >= 3.12 and pins torch, so it lives apart from dial's). Argument: a JSON
file listing the datasets, each with its expected counts and, optionally, reference arrays
(an ``.npz`` of float64 ``state`` and ``action``, frame by frame). Prints one JSON line.
"""

import json
import sys

import numpy as np
from lerobot.datasets.lerobot_dataset import LeRobotDataset

EPS = float(np.finfo(np.float32).eps)


def check(spec: dict) -> dict:
    ds = LeRobotDataset("dial/check", root=spec["root"], video_backend="pyav")
    assert ds.num_episodes == spec["episodes"], (ds.num_episodes, spec["episodes"])
    assert ds.num_frames == spec["frames"] == len(ds), (ds.num_frames, spec["frames"], len(ds))
    assert ds.fps == spec["fps"]
    seen = {"frames": 0, "videos": 0}
    reference = np.load(spec["reference"]) if spec.get("reference") else None
    for i in range(len(ds)):
        item = ds[i]
        assert item["task"] == spec["task"], item["task"]
        assert int(item["index"]) == i
        assert abs(float(item["timestamp"]) - int(item["frame_index"]) / ds.fps) < 1e-6
        if reference is not None:
            for key, column in (("observation.state", "state"), ("action", "action")):
                got = item[key].numpy().astype(np.float64)
                want = reference[column][i]
                assert np.allclose(got, want, rtol=EPS, atol=EPS), (i, key, got - want)
        for key in ds.meta.video_keys:
            frame = item[key]
            assert tuple(frame.shape) == (3, *spec["video_size"]), frame.shape
            assert float(frame.min()) >= 0.0 and float(frame.max()) <= 1.0
            seen["videos"] += 1
        seen["frames"] += 1
    return seen


def main() -> None:
    with open(sys.argv[1]) as f:
        specs = json.load(f)
    print(json.dumps([check(spec) for spec in specs]))


if __name__ == "__main__":
    main()
