"""Where a finger touches, in the world frame: from its tactile array or from its links.

A tactile array locates a contact on the distal pad face only. A contact on the end cap or on
a phalanx is located from the finger's kinematics and geometry instead: the contact point of
its links with whatever they touch, as an intrinsic contact sensor (a force/torque-sensing
finger with a known link surface) would report it. The simulator's contact point stands in
for that sensor's estimate: it lies on the link's surface, within half the penetration depth
(well under 1 mm) of the touched surface.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence

import mujoco
import numpy as np

from dial.robot.snapshot import FloatArray


def tactile_point(depths: FloatArray, taxels: FloatArray) -> FloatArray | None:
    """The depth-weighted centroid (3,) of the taxels that feel something, or None.

    ``depths``: a fingertip's taxel depths (m), any shape, in sensor order; ``taxels``:
    their (256, 3) world positions (``MujocoRobot.taxel_points``)."""
    weights = np.asarray(depths, dtype=np.float64).reshape(-1)
    if weights.max() <= 0.0:
        return None
    point: FloatArray = (weights @ taxels) / weights.sum()
    return point


def link_point(
    model: mujoco.MjModel, data: mujoco.MjData, bodies: frozenset[int], robot_root: int
) -> FloatArray | None:
    """The deepest contact point (3,) between the ``bodies`` and anything outside the robot
    (the first of equally deep ones, in MuJoCo's contact order).

    None when the finger touches nothing but the robot (or nothing at all). The contacts are
    read as arrays: a scene full of balls has a hundred and more of them. ``robot_root``: the
    root body of the robot's tree (its arm's base, which carries the hand)."""
    n = data.ncon
    if n == 0:
        return None
    contacts = data.contact
    b1 = model.geom_bodyid[contacts.geom1[:n]]
    b2 = model.geom_bodyid[contacts.geom2[:n]]
    finger = np.fromiter(bodies, dtype=b1.dtype, count=len(bodies))
    in1, in2 = np.isin(b1, finger), np.isin(b2, finger)
    other = np.where(in1, b2, b1)
    # One side is the finger (not both: the finger touching itself), the other not the robot.
    hits = np.flatnonzero((in1 != in2) & (model.body_rootid[other] != robot_root))
    if len(hits) == 0:
        return None
    deepest = hits[np.argmin(contacts.dist[:n][hits])]
    return np.array(contacts.pos[deepest], dtype=np.float64)


_BODY = mujoco.mjtObj.mjOBJ_BODY


class FingerContacts:
    """Which of a robot's fingers touch a body. The world model asks before each primitive
    while the hand holds something, so the fingers' links are one bit mask per body and the
    bodies' ids are looked up once."""

    def __init__(
        self, model: mujoco.MjModel, data: mujoco.MjData, fingers: Sequence[Collection[int]]
    ) -> None:
        """``fingers``: each finger's bodies (ids), in the profile's finger order."""
        self._model, self._data = model, data
        owner = np.zeros(model.nbody, dtype=np.int64)
        for k, bodies in enumerate(fingers):
            owner[sorted(bodies)] |= 1 << k
        self._owner = owner  # body id -> bit k set when the body is a link of finger k
        self._ids: dict[str, int] = {}

    def count(self, body: str, fingers: Sequence[int]) -> int:
        """How many of ``fingers`` (indices in profile order) have a link in contact with the
        body named ``body``."""
        d = self._data
        n = d.ncon
        if n == 0:
            return 0
        target = self._ids.get(body)
        if target is None:
            target = self._ids[body] = mujoco.mj_name2id(self._model, _BODY, body)
        of_geom = self._model.geom_bodyid
        b1, b2 = of_geom[d.contact.geom1[:n]], of_geom[d.contact.geom2[:n]]
        other = np.concatenate([b2[b1 == target], b1[b2 == target]])
        bits = int(np.bitwise_or.reduce(self._owner[other])) if len(other) else 0
        return sum((bits >> f) & 1 for f in fingers)


UPRIGHT = 0.7  # a contact normal within 45 deg of vertical: one body rests on the other


def resting_on(model: mujoco.MjModel, data: mujoco.MjData, body: str) -> tuple[str, ...]:
    """The names of the bodies that rest on the body named ``body``: in contact with it, above
    it (the contact normal within 45 deg of vertical, pointing up into them)."""
    n = data.ncon
    if n == 0:
        return ()
    target = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body))
    b1 = model.geom_bodyid[data.contact.geom1[:n]]
    b2 = model.geom_bodyid[data.contact.geom2[:n]]
    up = data.contact.frame[:n, 2]  # the normal's z, from geom1 to geom2
    above = np.concatenate(
        [b2[(b1 == target) & (up > UPRIGHT)], b1[(b2 == target) & (up < -UPRIGHT)]]
    )
    return tuple(model.body(int(b)).name for b in dict.fromkeys(above.tolist()))
