"""Sensing: snapshots into the log, contact waits and tests, contact points and fits."""

from __future__ import annotations

import numpy as np

from dial.instructions.catalogue import contact_condition
from dial.instructions.types import FINGERS
from dial.primitives.context import Context, RobotPrimitive, done, missed
from dial.robot.contact import contact_reading
from dial.robot.snapshot import FloatArray, Snapshot
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
    """``record_contact finger=F [into=SET] [at=now|stop] [source=tactile|links]``.

    Appends where the finger touches (world m) to a point set: the depth-weighted taxel
    centroid (``source=tactile``) or the contact point of its links (``source=links``), now
    or as it was when the latest guarded move sensing this finger stopped (``at=stop``).
    """

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        self.ctx = ctx
        finger = info.event.args["finger"]
        assert isinstance(finger, int)
        self.finger = finger
        self.set = str(info.event.args["into"])
        self.at = str(info.event.args["at"])
        self.source = str(info.event.args["source"])

    def sense(self, snapshot: Snapshot) -> Ended:
        name = FINGERS[self.finger]
        if self.at == "stop":
            stop = self.ctx.stops.get(self.finger)
            if stop is None:
                return missed(f"no guarded move stopped on a contact of the {name}")
            point = stop.tactile if self.source == "tactile" else stop.link
        else:
            touch = snapshot.touch(self.finger)
            point = touch.tactile if self.source == "tactile" else touch.link
        if point is None:
            where = "fingertip array" if self.source == "tactile" else "links"
            when = "at the stop" if self.at == "stop" else "now"
            return missed(f"the {name} {where} touched nothing {when}")
        points = self.ctx.point_sets.setdefault(self.set, [])
        points.append([float(x) for x in point])
        return done(point=point, set=self.set, count=len(points))


class Locate:
    """``locate "LOCATION" [also=OBJECT,...]``: the tool is at LOCATION of the true object.

    The object's believed position (and that of every ``also`` object) shifts by the tool's
    commanded position minus LOCATION's believed one, so that LOCATION and every other
    location relative to these objects follow what touch found. The commanded pose is where
    the planner starts the next motion from, the same frame the locations are reached in;
    the believed orientations are kept.
    """

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        self.ctx = ctx
        self.location = str(info.event.args["location"])
        also = info.event.args["also"]
        assert isinstance(also, tuple)
        self.also = tuple(str(a) for a in also)

    def sense(self, snapshot: Snapshot) -> Ended:
        world = self.ctx.world
        body = world.locations[self.location].body
        if body is None:  # the checker refuses this when the scene is known
            return Ended(Outcome.ERROR, f"location '{self.location}' is not relative to an object")
        tool, _ = self.ctx.arm_ik.fk(snapshot.arm_target)
        shift = tool - self.ctx.location(self.location)[0]
        aliases = {b: a for a, b in world.objects.items()}
        bodies = dict.fromkeys([body, *(world.objects[a] for a in self.also)])
        for b in bodies:
            pos, rot = self.ctx.believed[b]
            self.ctx.believed[b] = (pos + shift, rot)
        return done(shift=shift, objects=[aliases.get(b, b) for b in bodies])


class Fit:
    """``fit_plane SET`` and ``fit_superquadric SET``: least squares over a point set."""

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        self.ctx = ctx
        self.set = str(info.event.args["set"])
        self.kind = info.event.instruction.name

    def sense(self, snapshot: Snapshot) -> Ended:
        from dial.haptics import FitError, fit_plane, fit_superquadric  # SciPy: when fitting

        points = np.array(self.ctx.point_sets.get(self.set, []), dtype=np.float64).reshape(-1, 3)
        try:
            fit = fit_plane(points) if self.kind == "fit_plane" else fit_superquadric(points)
        except FitError as e:
            return Ended(Outcome.MISSED, f"point set '{self.set}': {e}")
        result = fit.as_result()
        self.ctx.results[self.set] = result
        return done(set=self.set, points=len(points), **result)
