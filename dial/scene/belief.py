"""The world model learns (DESIGN 5): what the robot believes of each object, and how it changes.

For each object the world model holds a believed pose (position (3,) m, rotation (3, 3)) and,
once something has measured it (or a world file says), a believed size: half-sizes (m) along
the object's body axes. Locations relative to an object follow its believed pose. It changes
in two ways:

- **A grasp carries it.** When a ``grasp_force`` ends done with two of its fingers (its one
  finger) on an object, the object is *held* (AL's AFFIX, TORBOL's GRASPED, the home-robot
  seed's ownership): its believed pose keeps the place in the tool frame it had at the grasp,
  and follows the commanded tool pose wherever the arm goes. When those fingers no longer
  touch it, it is released: it stays where the hand left it.
- **Touch measures it.** ``locate`` shifts an object to where the fingers found it; a fit with
  ``object=`` puts the object where the fitted shape is, and gives it the fitted size
  (:meth:`Beliefs.learn_superquadric`, :meth:`Beliefs.learn_plane`).

Every change is written to the run's log as a ``belief`` record: the object, why, and its
pose (and size) before and after (:meth:`Beliefs.entry`). Pure numpy: the caller says where
the tool is and which fingers touch what.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from dial.geometry import FloatArray, Pose, matrix_rpy, rpy_matrix
from dial.scene.world import World

Journal = Callable[[dict[str, object]], None]
Touching = Callable[[str, tuple[int, ...]], int]  # (body, fingers) -> how many touch it
Resting = Callable[[str], tuple[str, ...]]  # body -> the bodies resting on it (above it)


@dataclass(frozen=True)
class Feeling:
    """What the world model asks of the robot's senses, given by the engine (primitives never
    see the physics): how many of some fingers touch an object, which objects rest on one,
    and the simulated time (for the records). Without them (the preview, a teaching session)
    no grasp ever holds anything."""

    touching: Touching = lambda body, fingers: 0
    resting: Resting = lambda body: ()
    time: Callable[[], float] = lambda: 0.0


# A fit's contacts lie around its centre along an axis when their midrange is within this
# fraction of their extent from it (a solid touched all round, or on its top and at its bottom
# edge; not one touched from one side, or from the top down to below its middle only).
AROUND = 0.1
# ... and they touch both of its ends along the axis: on each side, a contact that lies further
# out along the axis than this fraction of its distance from the centre along any other axis
# (a point on the face or cap facing that way, not on a side that curves in towards it).
FACING = 0.8


@dataclass(frozen=True)
class Held:
    """An object in the hand: the fingers that grasped it, its believed pose in the
    (commanded) tool frame, and its believed pose when it was grasped; ``on``: the held
    object it rests on (a lid on a grasped pitcher), "" for an object the fingers hold."""

    fingers: tuple[int, ...]
    relative: Pose
    grasped: Pose
    on: str = ""


def compose(a: Pose, b: Pose) -> Pose:
    """The pose ``b`` given in frame ``a``, in the frame ``a`` is given in."""
    return a[0] + a[1] @ b[0], a[1] @ b[1]


def inverse(a: Pose) -> Pose:
    return -(a[1].T @ a[0]), a[1].T


def initial(
    world: World, model_poses: Mapping[str, Pose]
) -> tuple[dict[str, Pose], dict[str, FloatArray]]:
    """The believed poses and sizes at load: where the model has each body, except what the
    world file's ``[objects]`` tables say (their ``pos``, ``rpy`` and ``size``)."""
    poses = {body: (pos.copy(), rot.copy()) for body, (pos, rot) in model_poses.items()}
    sizes: dict[str, FloatArray] = {}
    for body, prior in world.priors.items():
        pos, rot = poses[body]
        if prior.pos is not None:
            pos = np.array(prior.pos, dtype=np.float64)
        if prior.rpy is not None:
            rot = rpy_matrix(prior.rpy)
        poses[body] = (pos, rot)
        if prior.size is not None:
            sizes[body] = np.array(prior.size, dtype=np.float64)
    return poses, sizes


class Beliefs:
    """The world model of one run: believed poses (shared with the primitives' context),
    believed sizes, and what the hand holds. ``journal`` receives each ``belief`` record;
    ``follow=False`` switches grasp following off (a grasp then changes nothing)."""

    def __init__(
        self,
        world: World,
        poses: dict[str, Pose],
        sizes: dict[str, FloatArray] | None = None,
        journal: Journal | None = None,
        follow: bool = True,
        feeling: Feeling | None = None,
    ) -> None:
        self.world, self.poses = world, poses
        self.feeling = feeling or Feeling()
        self.sizes: dict[str, FloatArray] = {} if sizes is None else sizes
        self.held: dict[str, Held] = {}
        self.journal = journal
        self.follow = follow
        self.changed = False  # a belief record was written

    def alias(self, body: str) -> str:
        """The world file's first name for a body (the body's own name if it has none)."""
        return next((a for a, b in self.world.objects.items() if b == body), body)

    def entry(self, body: str) -> dict[str, object]:
        """What is believed of a body, as log records and world files write it: ``pos`` m,
        ``rpy`` deg, and ``size`` (half-sizes, m; NaN, null in the log, along an axis not
        measured) when known."""
        pos, rot = self.poses[body]
        out: dict[str, object] = {"pos": pos.copy(), "rpy": list(matrix_rpy(rot))}
        if body in self.sizes:
            out["size"] = self.sizes[body].copy()
        return out

    def _note(self, body: str, why: str, before: dict[str, object], t: float, name: str) -> None:
        self.changed = True
        if self.journal is not None:
            record = {"object": name or self.alias(body), "body": body, "why": why}
            self.journal({**record, "before": before, "after": self.entry(body), "t": t})

    def set(
        self,
        body: str,
        pose: Pose,
        t: float,
        why: str,
        size: FloatArray | None = None,
        name: str = "",
    ) -> None:
        """Believe ``body`` at ``pose`` (and of ``size``), and log it."""
        before = self.entry(body)
        self.poses[body] = (
            np.array(pose[0], dtype=np.float64),
            np.array(pose[1], dtype=np.float64),
        )
        if size is not None:
            self.sizes[body] = np.array(size, dtype=np.float64)
        self._note(body, why, before, t, name)

    # -- grasps ------------------------------------------------------------------------------
    def grasp(self, tool: Pose, fingers: tuple[int, ...]) -> None:
        """A grasp with ``fingers`` ended done: every object that two of them (its one finger)
        touch is held from now on, at its believed pose in the tool frame ``tool``, and so is
        every object resting on it (the home-robot seed's ownership: a lid on a pitcher)."""
        if not self.follow:
            return
        self.update(tool)
        need, t = min(2, len(fingers)), self.feeling.time()
        objects = dict.fromkeys(self.world.objects.values())
        for body in objects:
            if body in self.held or self.feeling.touching(body, fingers) < need:
                continue
            self._hold(body, Held(fingers, self._in(tool, body), self.poses[body]), "grasped", t)
            for child in self.feeling.resting(body):
                if child in objects and child not in self.held:
                    held = Held(fingers, self._in(tool, child), self.poses[child], on=body)
                    self._hold(child, held, "carried", t)

    def _in(self, tool: Pose, body: str) -> Pose:
        return compose(inverse(tool), self.poses[body])

    def _hold(self, body: str, held: Held, why: str, t: float) -> None:
        self.held[body] = held
        self._note(body, why, self.entry(body), t, "")

    def update(self, tool: Pose) -> None:
        """Move every held object with the tool (at ``tool``), and release those its fingers
        no longer touch, and what rests on them: they stay where the hand left them."""
        if not self.held:
            return
        for body, held in self.held.items():
            self.poses[body] = compose(tool, held.relative)
        touching, t = self.feeling.touching, self.feeling.time()
        let_go = [b for b, h in self.held.items() if not h.on and touching(b, h.fingers) == 0]
        let_go += [b for b, h in self.held.items() if h.on and (h.on in let_go)]
        for body in let_go:
            held = self.held.pop(body)
            before = {"pos": held.grasped[0], "rpy": list(matrix_rpy(held.grasped[1]))}
            if body in self.sizes:
                before["size"] = self.sizes[body].copy()
            self._note(body, "released", before, t, "")

    # -- touch -------------------------------------------------------------------------------
    def locate(self, bodies: tuple[str, ...], shift: FloatArray, t: float, name: str) -> None:
        """``locate``: the bodies' believed positions shift by ``shift`` (m)."""
        for body in bodies:
            pos, rot = self.poses[body]
            self.set(body, (pos + shift, rot), t, "locate", name=name if body == bodies[0] else "")

    def learn_superquadric(
        self, body: str, fit: Mapping[str, object], points: FloatArray, t: float, name: str
    ) -> None:
        """The fitted superquadric is the object: its size the fitted half-sizes, each taken
        along the body axis closest to the fitted axis, and its origin at the fitted centre
        along each body axis on which the contacts ``points`` (N, 3) lie around that centre
        (their midrange along the axis within ``AROUND`` of their extent from it) and touch
        both its ends (:func:`_ends_touched`). Along an axis on which they do not (the bottom
        of a solid on its stand is never touched: along the vertical the contacts run from
        the top down to the bottom edge, or only to the middle of an ellipsoid, whose first
        fit, on a few contacts, may come out flat and centred between them), the fit closes
        the shape by its own assumptions, and the believed position along it stays. The
        believed orientation is kept: a symmetric solid's fitted axes are ambiguous (a
        cylinder's about its own axis), and the fits measure where an object is and how
        large, not how it turned."""
        centre = _vector(fit["centre"])
        axes = np.array(fit["rotation"], dtype=np.float64)
        half = _vector(fit["size"])
        pos, rot = self.poses[body]
        along = (np.asarray(points, dtype=np.float64) - centre) @ rot  # body axes
        low, high = along.min(axis=0), along.max(axis=0)
        around = np.abs(low + high) / 2.0 <= AROUND * (high - low)
        new = pos + rot @ np.where(around & _ends_touched(along), rot.T @ (centre - pos), 0.0)
        size = half[_closest(rot, axes)]
        self.set(body, (new, rot), t, "fit_superquadric", size, name)

    def learn_plane(self, body: str, fit: Mapping[str, object], t: float, name: str) -> None:
        """A fitted plane is a face of the object, and the traced points span it edge to edge:
        the object moves in the plane to put its origin over the face's centre (``centre``:
        halfway between the extreme points along each in-plane axis), and across it only when
        its size along the face's normal is known (its origin is then half that size behind
        the face). The face's extents are its size along the two body axes closest to the
        plane's axes; its size along the normal stays as it was (NaN: not known)."""
        pos, rot = self.poses[body]
        normal, face = _vector(fit["normal"]), _vector(fit["centre"])
        axes = np.array(fit["axes"], dtype=np.float64)
        extents = _vector(fit["extents"])
        size = self.sizes.get(body, np.full(3, np.nan)).copy()
        across = float(size[int(np.argmax(np.abs(rot.T @ normal)))])
        new = face + normal * ((pos - face) @ normal if np.isnan(across) else -across)
        for k in range(2):
            size[int(np.argmax(np.abs(rot.T @ axes[k])))] = extents[k] / 2.0
        self.set(body, (new, rot), t, "fit_plane", size, name)


def _ends_touched(along: FloatArray) -> FloatArray:
    """For each axis, whether the contacts ``along`` (N, 3; from the fitted centre, along the
    body axes) touch both its ends: on each side a contact within the cone of ``FACING``
    about the axis. A solid touched on its top and round its middle, never underneath, is not
    touched at its bottom end: however its fit closes the shape below, the contacts do not
    say where its centre is along the vertical."""
    out = np.zeros(3, dtype=bool)
    for k in range(3):
        other = np.abs(np.delete(along, k, axis=1)).max(axis=1)
        end = np.abs(along[:, k]) >= FACING * other
        out[k] = bool((end & (along[:, k] > 0)).any() and (end & (along[:, k] < 0)).any())
    return out


def _vector(value: object) -> FloatArray:
    return np.array(value, dtype=np.float64).reshape(-1)


def _closest(rot: FloatArray, axes: FloatArray) -> list[int]:
    """For each body axis (the columns of ``rot``), the fitted axis (a column of ``axes``)
    closest to it, each fitted axis used once: the best-aligned body axis chooses first."""
    closeness = np.abs(rot.T @ axes)  # [body axis, fitted axis]
    out = [0, 0, 0]
    taken: set[int] = set()
    for i in np.argsort(-closeness.max(axis=1)):
        j = max((j for j in range(3) if j not in taken), key=lambda j: closeness[i, j])
        taken.add(j)
        out[int(i)] = j
    return out
