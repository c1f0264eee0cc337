"""A robot profile's names resolved against its compiled MJCF: every problem at its key.

What ``dial robots check`` reports beyond the file's structure: a name that is not in the
model, or names a part of the wrong kind (a sensor that is not a tactile array, an actuator
that is not a position servo on that joint), a joint without limits, and figures that
disagree with the model (the tendons' moment arm, the drives' force limit).
"""

from __future__ import annotations

from difflib import get_close_matches

import mujoco
import numpy as np

from dial.robots.fields import Problem
from dial.robots.locate import Path
from dial.robots.profile import Arm, Finger, Hand, Parts

_HINGE_OR_SLIDE = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
_KINDS = {
    mujoco.mjtObj.mjOBJ_JOINT: "joint",
    mujoco.mjtObj.mjOBJ_ACTUATOR: "actuator",
    mujoco.mjtObj.mjOBJ_SENSOR: "sensor",
    mujoco.mjtObj.mjOBJ_SITE: "site",
}
TOLERANCE = 1e-9  # relative: figures the profile states and the model holds


class _Resolver:
    def __init__(self, parts: Parts, model: mujoco.MjModel, file: str) -> None:
        self.parts, self.model, self.file = parts, model, file
        self.problems: list[Problem] = []

    def fail(self, path: Path, message: str) -> None:
        self.problems.append(Problem(path, message))

    def find(self, kind: mujoco.mjtObj, name: str, path: Path) -> int | None:
        """The id of ``name``, or None with a problem that suggests close names."""
        i = int(mujoco.mj_name2id(self.model, kind, name))
        if i >= 0:
            return i
        what = _KINDS[kind]
        count = {
            mujoco.mjtObj.mjOBJ_JOINT: self.model.njnt,
            mujoco.mjtObj.mjOBJ_ACTUATOR: self.model.nu,
            mujoco.mjtObj.mjOBJ_SENSOR: self.model.nsensor,
            mujoco.mjtObj.mjOBJ_SITE: self.model.nsite,
        }[kind]
        names = [mujoco.mj_id2name(self.model, kind, k) or "" for k in range(count)]
        close = get_close_matches(name, names, n=2)
        hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
        self.fail(path, f"no {what} '{name}' in {self.file}{hint}")
        return None

    def joint(self, name: str, path: Path) -> int | None:
        """A limited hinge or slide joint."""
        j = self.find(mujoco.mjtObj.mjOBJ_JOINT, name, path)
        if j is None:
            return None
        if int(self.model.jnt_type[j]) not in _HINGE_OR_SLIDE:
            self.fail(
                path, f"joint '{name}' is not a hinge or slide; expected one degree of freedom"
            )
            return None
        if not self.model.jnt_limited[j]:
            self.fail(path, f"joint '{name}' has no limit in {self.file}; expected a range")
        return j

    def servo(self, name: str, joint: int | None, path: Path) -> int | None:
        """A position actuator that drives ``joint``."""
        a = self.find(mujoco.mjtObj.mjOBJ_ACTUATOR, name, path)
        if a is None or joint is None:
            return a
        m = self.model
        on = (
            m.actuator_trntype[a] == int(mujoco.mjtTrn.mjTRN_JOINT)
            and m.actuator_trnid[a, 0] == joint
        )
        if not on:
            self.fail(path, f"actuator '{name}' does not drive joint '{m.joint(joint).name}'")
        elif not _is_position(m, a):
            self.fail(path, f"actuator '{name}' is not a position servo (kp (ctrl - q) - kv qdot)")
        return a

    def sensor_on(self, kind: mujoco.mjtSensor, target: int) -> int | None:
        m = self.model
        hits = np.flatnonzero((m.sensor_type == int(kind)) & (m.sensor_objid == target))
        return int(hits[0]) if len(hits) else None


def _is_position(m: mujoco.MjModel, a: int) -> bool:
    fixed = m.actuator_gaintype[a] == int(mujoco.mjtGain.mjGAIN_FIXED)
    affine = m.actuator_biastype[a] == int(mujoco.mjtBias.mjBIAS_AFFINE)
    return bool(fixed and affine and m.actuator_biasprm[a, 1] == -m.actuator_gainprm[a, 0])


def resolve(parts: Parts, model: mujoco.MjModel) -> list[Problem]:
    """Every problem of the names and figures of the sound ``parts`` against ``model``."""
    file = parts.top[2].name if parts.top else "the model"
    r = _Resolver(parts, model, file)
    if parts.arm is not None:
        _arm(r, parts.arm)
    drives: list[int] = []
    for i, finger in enumerate(parts.fingers or ()):
        drives += _finger(r, i, finger, parts.hand)
    _twice(r)
    if parts.limits is not None and parts.hand is not None:
        _load_limit(r, drives, parts.limits.load)
    return r.problems


def _arm(r: _Resolver, arm: Arm) -> None:
    for i, (joint, servo) in enumerate(zip(arm.joints, arm.servos, strict=True)):
        j = r.joint(joint, ("arm", "joints", i))
        r.servo(servo, j, ("arm", "servos", i))
        if j is not None and r.model.jnt_limited[j]:
            lo, hi = r.model.jnt_range[j]
            if not lo <= arm.home[i] <= hi:
                r.fail(("arm", "home", i), f"{arm.home[i]:g} rad is outside {joint}'s range")
    r.find(mujoco.mjtObj.mjOBJ_SITE, arm.tool_site, ("arm", "tool_site"))


def _finger(r: _Resolver, i: int, finger: Finger, hand: Hand | None) -> list[int]:
    """Check one finger; return its drives (servos or tendon actuators)."""
    p: Path = ("fingers", i)
    r.find(mujoco.mjtObj.mjOBJ_SITE, finger.tip_site, (*p, "tip_site"))
    if finger.tactile is not None:
        _tactile(r, finger.tactile, (*p, "tactile"), hand)
    drives = []
    for k, name in enumerate(finger.joints):
        j = r.joint(name, (*p, "joints", k))
        if hand is None:
            continue
        if hand.load == "tendon":
            for side in ("flexors", "extensors"):
                a = _tendon(r, getattr(finger, side)[k], j, side, (*p, side, k), hand.lever)
                drives += [] if a is None else [a]
            continue
        a = r.servo(finger.servos[k], j, (*p, "servos", k))
        drives += [] if a is None else [a]
        torque = hand.load == "joint"
        if torque and j is not None and r.sensor_on(mujoco.mjtSensor.mjSENS_JOINTACTFRC, j) is None:
            r.fail(
                (*p, "joints", k),
                f"no jointactuatorfrc sensor on joint '{name}' "
                '(hand.load = "joint" reads one per joint)',
            )
    return drives


def _tactile(r: _Resolver, name: str, path: Path, hand: Hand | None) -> None:
    s = r.find(mujoco.mjtObj.mjOBJ_SENSOR, name, path)
    if s is None:
        return
    kind = mujoco.mjtSensor(int(r.model.sensor_type[s])).name.removeprefix("mjSENS_").lower()
    kind = kind.replace("actfrc", "actuatorfrc")  # the MJCF element's name
    if kind != "tactile":
        r.fail(path, f"sensor '{name}' is a {kind} sensor; expected a tactile sensor")
        return
    if hand is None:
        return
    rows, cols = hand.taxels
    if r.model.sensor_dim[s] != 3 * rows * cols:
        have = int(r.model.sensor_dim[s]) // 3
        r.fail(path, f"sensor '{name}' has {have} taxels; expected {rows}x{cols} (hand.taxels)")


def _tendon(
    r: _Resolver, name: str, joint: int | None, side: str, path: Path, lever: float
) -> int | None:
    """A tendon actuator on a fixed tendon of ``joint``, with a tension sensor."""
    a = r.find(mujoco.mjtObj.mjOBJ_ACTUATOR, name, path)
    if a is None:
        return None
    m = r.model
    if m.actuator_trntype[a] != int(mujoco.mjtTrn.mjTRN_TENDON):
        r.fail(path, f"actuator '{name}' does not pull a tendon; expected a tendon actuator")
        return None
    if r.sensor_on(mujoco.mjtSensor.mjSENS_ACTUATORFRC, a) is None:
        r.fail(path, f"no actuatorfrc sensor on '{name}'; expected its tension sensor")
    tendon = int(m.actuator_trnid[a, 0])
    adr, num = int(m.tendon_adr[tendon]), int(m.tendon_num[tendon])
    on = [k for k in range(adr, adr + num) if m.wrap_objid[k] == joint]
    if joint is None:
        return a
    if len(on) != 1:
        r.fail(path, f"the tendon of '{name}' does not act on its finger's joint")
        return a
    coef = float(m.wrap_prm[on[0]])
    if abs(abs(coef) - lever) > TOLERANCE * lever:
        r.fail(
            path,
            f"the tendon of '{name}' has a {abs(coef):g} m moment arm; hand.lever says {lever:g}",
        )
    if (coef < 0) != (side == "flexors"):
        r.fail(path, f"'{name}' pulls its joint the wrong way for one of the {side}")
    return a


def _twice(r: _Resolver) -> None:
    """No joint is named by two fingers, or by a finger and the arm."""
    arm = r.parts.arm.joints if r.parts.arm else ()
    seen: dict[str, Path] = {n: ("arm", "joints", i) for i, n in enumerate(arm)}
    for i, finger in enumerate(r.parts.fingers or ()):
        for k, name in enumerate(finger.joints):
            if name in seen:
                r.fail(("fingers", i, "joints", k), f"joint '{name}' is named twice")
            seen[name] = ("fingers", i, "joints", k)


def _load_limit(r: _Resolver, drives: list[int], load: float) -> None:
    """``limits.load`` is the largest force the hand's drives exert (tension or torque)."""
    if not drives:
        return
    m = r.model
    limited = m.actuator_forcelimited[drives].astype(bool)
    if not limited.all():
        name = m.actuator(drives[int(np.argmin(limited))]).name
        r.fail(
            ("limits", "load"),
            f"actuator '{name}' has no force limit in {r.file}; "
            "expected a forcerange (the drive's limit)",
        )
        return
    most = float(np.abs(m.actuator_forcerange[drives]).max())
    if abs(most - load) > TOLERANCE * most:
        r.fail(
            ("limits", "load"),
            f"the hand's drives exert at most {most:g} in {r.file}; "
            f"expected limits.load = {most:g}",
        )
