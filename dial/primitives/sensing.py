"""Sensing: snapshots into the log, contact waits and tests, contact points and fits."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from dial.instructions.types import FINGERS, Contact
from dial.primitives.context import Context, RobotPrimitive, done, missed
from dial.robot.contact import force_reading, position_reading, tactile_reading
from dial.robot.snapshot import FloatArray, Snapshot
from dial.scheduler.primitive import Allotment, Ended, Now, Outcome

if TYPE_CHECKING:
    from dial.haptics import PlaneFit, SuperquadricFit


class Get:
    """``get_joints``, ``get_forces``, ``get_tactile``, ``get_wrist``: record what ``read``
    takes from the snapshot."""

    def __init__(self, read: Callable[[Snapshot], dict[str, object]]) -> None:
        self.read = read

    def sense(self, snapshot: Snapshot) -> Ended:
        return done(**self.read(snapshot))


NO_BASELINE = (0.0,) * 16  # a force reading measured from zero: the differentials' value


def contact_value(contact: Contact, snapshot: Snapshot, baseline: Sequence[float]) -> float:
    """The reading (m or N) a contact condition compares with its threshold, from the
    snapshot (:mod:`dial.robot.contact`); a force reading is the change from ``baseline``
    (16 joint loads). A dropped-out sensor reads 0, as the robot's guards read it."""
    kind, finger = contact.kind, contact.finger
    if (kind, finger) in snapshot.dropped:
        return 0.0
    if kind == "tactile":
        return tactile_reading(snapshot.tactile[finger])
    if kind == "force":
        return force_reading(snapshot.differentials.tolist(), baseline, finger)
    return position_reading(snapshot.hand_target, snapshot.hand_q, finger)


class ContactWait(RobotPrimitive):
    """``position_contact``, ``force_contact``, ``tactile_contact`` in a diagram: wait until
    the contact is signalled (a force change counts from the run's start)."""

    def __init__(self, ctx: Context, allotted: Allotment, contact: Contact) -> None:
        super().__init__(ctx, allotted)
        self.contact = contact

    def start(self, snapshot: Snapshot) -> None:
        self.baseline = snapshot.differentials.tolist()

    def step(self, snapshot: Snapshot, now: Now) -> Ended | None:
        value = contact_value(self.contact, snapshot, self.baseline)
        return done(value=value) if value >= self.contact.threshold else None


class ContactTest:
    """A contact instruction as a condition-only event: is the contact there now?"""

    def __init__(self, contact: Contact) -> None:
        self.contact = contact

    def sense(self, snapshot: Snapshot) -> Ended:
        kind, finger, threshold = self.contact
        value = contact_value(self.contact, snapshot, NO_BASELINE)
        if value >= threshold:
            return done(value=value)
        return missed(f"no {kind} contact on the {FINGERS[finger]}", value=value)


class RecordContact:
    """``record_contact finger=F [into=SET] [at=now|stop] [source=tactile|links]``.

    Appends where the finger touches (world m) to a point set: the depth-weighted taxel
    centroid (``source=tactile``) or the contact point of its links (``source=links``), now
    or as it was when the latest guarded move sensing this finger stopped (``at=stop``).
    """

    def __init__(self, ctx: Context, finger: int, into: str, at: str, source: str) -> None:
        self.ctx, self.finger, self.set, self.at, self.source = ctx, finger, into, at, source

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

    def __init__(self, ctx: Context, location: str, also: tuple[str, ...]) -> None:
        self.ctx, self.location, self.also = ctx, location, also

    def sense(self, snapshot: Snapshot) -> Ended:
        world = self.ctx.world
        body = world.locations[self.location].body
        if body is None:  # the checker refuses this when the scene is known
            return Ended(Outcome.ERROR, f"location '{self.location}' is not relative to an object")
        tool, _ = self.ctx.arm_ik.fk(snapshot.arm_target)
        shift = tool - self.ctx.location(self.location)[0]
        aliases = {b: a for a, b in world.objects.items()}
        bodies = tuple(dict.fromkeys([body, *(world.objects[a] for a in self.also)]))
        self.ctx.world_model.locate(bodies, shift, snapshot.time, self.location_object())
        return done(shift=shift, objects=[aliases.get(b, b) for b in bodies])

    def location_object(self) -> str:
        """The alias the location is written relative to."""
        return next(
            (a for a, b in self.ctx.world.objects.items()
             if b == self.ctx.world.locations[self.location].body),
            "",
        )  # fmt: skip


class Fit:
    """``fit_plane SET`` and ``fit_superquadric SET``: ``fit`` (least squares) over a point
    set; with ``learns`` (an object's alias), the world model takes the fit as that object's
    position and size (:mod:`dial.scene.belief`)."""

    def __init__(
        self,
        ctx: Context,
        point_set: str,
        fit: Callable[[FloatArray], PlaneFit | SuperquadricFit],
        learns: str | None = None,
    ) -> None:
        self.ctx, self.set, self.fit, self.object = ctx, point_set, fit, learns

    def sense(self, snapshot: Snapshot) -> Ended:
        from dial.haptics import FitError, PlaneFit  # SciPy: only a run that fits loads it

        points = np.array(self.ctx.point_sets.get(self.set, []), dtype=np.float64).reshape(-1, 3)
        try:
            fit = self.fit(points)
        except FitError as e:
            return Ended(Outcome.MISSED, f"point set '{self.set}': {e}")
        result = fit.as_result()
        self.ctx.results[self.set] = result
        if self.object is not None:  # the object measured: the world model learns it
            body, model = self.ctx.world.objects[self.object], self.ctx.world_model
            self.ctx.refresh()
            if isinstance(fit, PlaneFit):
                model.learn_plane(body, result, snapshot.time, self.object)
            else:
                model.learn_superquadric(body, result, points, snapshot.time, self.object)
        return done(set=self.set, points=len(points), **result)
