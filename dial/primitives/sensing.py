"""Sensing: snapshots into the log, contact waits and tests, contact points and fits."""

from __future__ import annotations

import numpy as np

from dial.backend.contact import contact_reading
from dial.backend.snapshot import FloatArray, Snapshot
from dial.haptics import FitError, fit_plane, fit_superquadric
from dial.instructions.catalogue import contact_condition
from dial.instructions.types import FINGERS
from dial.primitives.context import Context, RobotPrimitive, done, missed
from dial.scheduler.types import Ended, Now, Outcome, RunInfo


class Get:
    """``get_joints``, ``get_forces``, ``get_tactile``, ``get_wrist``: record a snapshot."""

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        self.what = info.event.instruction.name

    def sense(self, snapshot: Snapshot) -> Ended:
        if self.what == "get_joints":
            return done(hand_q=snapshot.hand_q, arm_q=snapshot.arm_q)
        if self.what == "get_forces":
            return done(tensions=snapshot.tensions)
        if self.what == "get_tactile":
            return done(tactile=snapshot.tactile)
        return done(pos=snapshot.tool_pos, rot=snapshot.tool_rot)


def contact_value(kind: str, snapshot: Snapshot, finger: int, baseline: FloatArray | None) -> float:
    """The reading a contact condition compares with its threshold (m or N); a dropped-out
    sensor reads 0, as the driver's guards read it."""
    if (kind, finger) in snapshot.dropped:
        return 0.0
    return contact_reading(
        kind,
        finger,
        snapshot.tactile[finger],
        snapshot.differentials,
        snapshot.hand_target,
        snapshot.hand_q,
        baseline,
    )


class ContactWait(RobotPrimitive):
    """``position_contact``, ``force_contact``, ``tactile_contact``.

    In a diagram: wait until the contact is signalled (a force change counts from the
    run's start). As a condition-only event: is the contact there now (:meth:`sense`)?
    """

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        super().__init__(ctx, info)
        self.kind, self.finger, self.threshold = contact_condition(
            info.event.instruction, info.event.args
        )

    def start(self, snapshot: Snapshot) -> None:
        self.baseline = snapshot.differentials.copy()

    def step(self, snapshot: Snapshot, now: Now) -> Ended | None:
        value = contact_value(self.kind, snapshot, self.finger, self.baseline)
        return done(value=value) if value >= self.threshold else None

    def sense(self, snapshot: Snapshot) -> Ended:
        value = contact_value(self.kind, snapshot, self.finger, None)
        if value >= self.threshold:
            return done(value=value)
        return missed(f"no {self.kind} contact on the {FINGERS[self.finger]}", value=value)


class RecordContact:
    """``record_contact finger=F [into=SET]``: the depth-weighted taxel centroid, world frame."""

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        self.ctx = ctx
        finger = info.event.args["finger"]
        assert isinstance(finger, int)
        self.finger = finger
        self.set = str(info.event.args["into"])

    def sense(self, snapshot: Snapshot) -> Ended:
        depth = snapshot.tactile[self.finger].reshape(-1)
        if depth.max() <= 0.0:
            return missed(f"the {FINGERS[self.finger]} fingertip touches nothing")
        points = self.ctx.robot.taxel_points(self.finger)
        point = (depth @ points) / depth.sum()
        self.ctx.point_sets.setdefault(self.set, []).append([float(x) for x in point])
        return done(point=point, set=self.set, count=len(self.ctx.point_sets[self.set]))


class Fit:
    """``fit_plane SET`` and ``fit_superquadric SET``: least squares over a point set."""

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        self.ctx = ctx
        self.set = str(info.event.args["set"])
        self.kind = info.event.instruction.name

    def sense(self, snapshot: Snapshot) -> Ended:
        points = np.array(self.ctx.point_sets.get(self.set, []), dtype=np.float64).reshape(-1, 3)
        try:
            fit = fit_plane(points) if self.kind == "fit_plane" else fit_superquadric(points)
        except FitError as e:
            return Ended(Outcome.MISSED, f"point set '{self.set}': {e}")
        result = fit.as_result()
        self.ctx.results[self.set] = result
        return done(set=self.set, points=len(points), **result)
