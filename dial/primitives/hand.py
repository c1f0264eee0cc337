"""Hand primitives: named poses, grasp with force, limp, and Cartesian fingertip moves."""

from __future__ import annotations

import numpy as np

from dial.geometry import smooth, smooth_array
from dial.primitives.context import Context, RobotPrimitive, done, missed
from dial.robot.protocol import Course
from dial.robot.slots import still
from dial.robot.snapshot import FloatArray, Snapshot
from dial.scheduler.primitive import Allotment, Ended, Now, progress_after


def _bits(mask: int) -> list[int]:
    return [k for k in range(16) if mask >> k & 1]


class HandPose(RobotPrimitive):
    """``hand_pose "NAME" [fingers=MASK]``: the joints of the world's pose ``pose`` (only
    those in ``fingers``, a mask); GOTO for ``#``, interpolated for ``#===``."""

    def __init__(self, ctx: Context, allotted: Allotment, pose: str, fingers: int) -> None:
        super().__init__(ctx, allotted)
        self.pose, self.fingers = pose, fingers

    def start(self, snapshot: Snapshot) -> None:
        pose = self.ctx.world.poses[self.pose]
        self.mask = pose.mask & self.fingers
        self.q0 = snapshot.hand_target.copy()
        self.q1 = self.q0.copy()
        for bit, angle in pose.angles.items():
            self.q1[bit] = angle

    def step(self, snapshot: Snapshot, now: Now) -> Ended | None:
        self.slots.joints(self.mask, self.q0 + (self.q1 - self.q0) * smooth(now.progress))
        return None

    open_loop = True

    def course(self, first: int, count: int) -> Course:
        span, n = self.allotted.span, self.allotted.periods_per_tick
        progress = [progress_after(k, span, n) for k in range(first, first + count)]
        s = smooth_array(np.asarray(progress, dtype=np.float64))
        return self.slots.joints_course(self.mask, self.q0 + (self.q1 - self.q0) * s[:, None])


class GraspForce(RobotPrimitive):
    """``grasp_force "JMASK_TMASK FORCE"`` (the paper's GRASP WITH FORCE).

    The joints in JMASK close at ``speed``. A finger stops closing when any of
    its tendon-masked joints feels a flexor-minus-extensor tension of FORCE (a
    finger with no tendon-masked joint stops when any of its own joints does).
    The run is done when every finger with a tendon-masked joint has stopped,
    and missed if they all reach their joint limits first.
    """

    def __init__(
        self, ctx: Context, allotted: Allotment, jmask: int, tmask: int, force: float, speed: float
    ) -> None:
        super().__init__(ctx, allotted)
        self.jmask, self.tmask, self.force, self.speed = jmask, tmask, force, speed

    def start(self, snapshot: Snapshot) -> None:
        self.rate = self.speed * self.allotted.period
        self.target = snapshot.hand_target.copy()
        self.fingers = sorted({k // 4 for k in _bits(self.jmask)})
        self.watched = {
            f: [k for k in _bits(self.tmask) if k // 4 == f]
            or [k for k in _bits(self.jmask) if k // 4 == f]
            for f in self.fingers
        }
        self.stopped: dict[int, float] = {}
        self.jbits, self.tbits = _bits(self.jmask), _bits(self.tmask)
        self.monitored = {k // 4 for k in self.tbits} or set(self.fingers)
        # The set-points as Python floats: a few joints a period, cheaper than numpy's calls.
        self.q, self.limits = self.target.tolist(), self.ctx.view.hand_range[:, 1].tolist()
        self.closing = list(self.jbits)  # the joints of the fingers not stopped yet

    def step(self, snapshot: Snapshot, now: Now) -> Ended | None:
        diff = snapshot.differentials.tolist()
        stopped = self.stopped
        for f in self.fingers:
            if f not in stopped and max(diff[k] for k in self.watched[f]) >= self.force:
                stopped[f] = now.sim_time
                self.closing = [k for k in self.jbits if k // 4 not in stopped]
        q, limits, rate, closing = self.q, self.limits, self.rate, self.closing
        for k in closing:
            q[k] = min(q[k] + rate, limits[k])
        self.target[:] = q
        self.slots.joints(self.jmask, self.target)
        if self.monitored <= stopped.keys():
            self.ctx.world_model.grasp(self.ctx.tool(), tuple(self.fingers))
            return done(forces=self._forces(diff))
        if all(q[k] >= limits[k] for k in closing) and not (self.monitored & stopped.keys()):
            message = "the fingers closed fully without reaching the force"
            return missed(message, forces=self._forces(diff))
        return None

    def _forces(self, diff: list[float]) -> dict[str, float]:
        return {f"j{k}": diff[k] for k in self.tbits}


class Limp(RobotPrimitive):
    """``limp [fingers=MASK] [save=NAME]``: back-drivable joints; the reached pose is recorded."""

    def __init__(self, ctx: Context, allotted: Allotment, mask: int, save: str | None) -> None:
        super().__init__(ctx, allotted)
        self.mask, self.save = mask, save
        self.limp = False

    def start(self, snapshot: Snapshot) -> None:
        self.slots.limp(self.mask, True)
        self.limp = True

    def step(self, snapshot: Snapshot, now: Now) -> Ended | None:
        return None

    open_loop = True  # the limp joints follow their measured angle in the driver

    def course(self, first: int, count: int) -> Course:
        return still

    def finish(self, snapshot: Snapshot) -> Ended:
        self.slots.limp(self.mask, False)
        self.limp = False
        pose = {f"j{k}": float(np.degrees(snapshot.hand_q[k])) for k in _bits(self.mask)}
        save = self.save
        return done(pose_deg=pose, **({"saved_as": save} if save else {}))

    def stop(self) -> None:  # ended early (preempted, aborted): stiffen where the joints are
        if self.limp:
            self.slots.limp(self.mask, False)


class FingerMove(RobotPrimitive):
    """``finger_move finger=F DX DY DZ [frame=palm|world]``: a straight fingertip line by IK."""

    def __init__(
        self,
        ctx: Context,
        allotted: Allotment,
        finger: int,
        displacement: tuple[float, float, float],
        frame: str,
    ) -> None:
        super().__init__(ctx, allotted)
        self.finger, self.displacement, self.frame = finger, displacement, frame

    def start(self, snapshot: Snapshot) -> None:
        self.arm_q = snapshot.arm_target.copy()
        self.hand = snapshot.hand_target.copy()
        ik = self.ctx.finger_ik
        self.tip0 = ik.tip(self.arm_q, self.hand, self.finger)
        d = np.array(self.displacement, dtype=np.float64)
        self.delta: FloatArray = snapshot.tool_rot @ d if self.frame == "palm" else d
        self.mask = 0xF << (4 * self.finger)

    def step(self, snapshot: Snapshot, now: Now) -> Ended | None:
        goal = self.tip0 + self.delta * smooth(now.progress)
        self.hand = self.ctx.finger_ik.track(self.finger, goal, self.arm_q, self.hand)
        self.slots.joints(self.mask, self.hand)
        return None
