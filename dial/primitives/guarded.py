"""``guarded_move``: move along a line until contact, checked at every physics step.

The motion runs at ``speed`` in simulated time (a safe approach speed, not tick
time), so a guarded move that outlasts its ticks stretches its last tick. The
guard is tested by the robot, which freezes the effector at the physics step
where the contact is first sensed; the run then ends ``done`` with the contact,
or ``missed`` when it reaches ``max`` travel without one. With ``press`` the
effector is then set that much further on from where it stopped, so that a
light contact holds for the sensing that follows instead of fading as the
servo settles. Where the finger touched at the physics step of the stop is kept
for ``record_contact at=stop``: a light contact may fade within tens of ms.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from dial.instructions.types import FINGERS, ContactKind
from dial.primitives.context import Context, RobotPrimitive, done, missed
from dial.robot.snapshot import FloatArray, Snapshot
from dial.scheduler.primitive import Allotment, Ended, Now


class GuardedMove(RobotPrimitive):
    """Moves ``finger`` (None: the arm's tool) along ``displacement`` (m, in ``frame``) at
    ``speed`` (m/s), for ``travel`` (m; None: the displacement's length), until one of the
    ``until`` conditions holds on a ``sense`` finger; then ``press`` (m) further on."""

    def __init__(
        self,
        ctx: Context,
        allotted: Allotment,
        *,
        finger: int | None,
        displacement: tuple[float, float, float],
        travel: float | None,
        frame: str,
        speed: float,
        press: float,
        until: Sequence[tuple[ContactKind, float]],
        sense: tuple[int, ...],
    ) -> None:
        super().__init__(ctx, allotted)
        self.finger = finger
        d = np.array(displacement, dtype=np.float64)
        self.length = travel if travel is not None else float(np.linalg.norm(d))
        self.direction = d / np.linalg.norm(d)
        self.frame, self.speed, self.press = frame, speed, press
        self.until, self.sense = tuple(until), sense
        self.guard = 0

    def start(self, snapshot: Snapshot) -> None:
        world = self.frame == "world"
        self.delta = self.direction if world else snapshot.tool_rot @ self.direction
        self.arm_q = snapshot.arm_target.copy()
        self.hand = snapshot.hand_target.copy()
        ik = self.ctx.arm_ik
        if self.finger is None:
            self.p0, self.r0 = ik.fk(self.arm_q)
        else:
            self.p0 = self.ctx.finger_ik.tip(self.arm_q, self.hand, self.finger)
        effector = "arm" if self.finger is None else FINGERS[self.finger]
        self.guard = self.slots.guard(effector, self.until, self.sense)
        for f in self.sense:  # a stop recorded before this move is not this move's contact
            self.ctx.stops.pop(f, None)

    def step(self, snapshot: Snapshot, now: Now) -> Ended | None:
        trip = snapshot.trips.get(self.guard)
        travel = min(self.speed * (now.elapsed - self.allotted.period), self.length)
        if trip is not None:
            self.ctx.stops[trip.finger] = trip.touch
            if self.press > 0.0:  # the driver froze the effector at contact: lean in a little
                if self.finger is None:
                    pos = self.ctx.arm_ik.fk(snapshot.arm_q)[0]
                    self._command(pos + self.delta * self.press, snapshot.arm_q, self.hand, 5)
                else:
                    tip = self.ctx.finger_ik.tip(snapshot.arm_q, snapshot.hand_q, self.finger)
                    self._command(tip + self.delta * self.press, self.arm_q, snapshot.hand_q, 5)
            return done(
                kind=trip.kind,
                finger=FINGERS[trip.finger],
                value=trip.value,
                time=trip.time,
                step=trip.step,
                travel=travel,
            )
        if travel >= self.length:
            return missed(f"no contact within {self.length * 1000:.0f} mm", travel=travel)
        goal = self.p0 + self.delta * (travel + self.speed * self.allotted.period)
        self._command(goal, self.arm_q, self.hand, 2)
        return None

    def _command(
        self, goal: FloatArray, arm_q: FloatArray, hand_q: FloatArray, iterations: int
    ) -> None:
        """Set the moving effector toward ``goal`` (tool or fingertip position, world m)."""
        if self.finger is None:
            self.arm_q = self.ctx.arm_ik.track(goal, self.r0, arm_q, iterations)
            self.slots.arm(self.arm_q)
        else:
            self.hand = self.ctx.finger_ik.track(self.finger, goal, arm_q, hand_q, iterations)
            self.slots.joints(0xF << (4 * self.finger), self.hand)

    def stop(self) -> None:
        self.slots.unguard(self.guard)
