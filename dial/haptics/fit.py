"""Least-squares fits to haptic contact points: a plane, and Solina's superquadric.

Points are fingertip contacts in the world frame, in metres, as an (N, 3) array. Both fits are
deterministic: no randomness, so the same points give the same fit bit for bit. ``as_result()``
gives the dict that the scene criteria (``dial.scene.evaluate``) read, in plain JSON types.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from dial.haptics.lines import trace_angle

Array = npt.NDArray[np.float64]

# Degeneracy tests on the singular values s0 >= s1 >= s2 of the centred points.
RANK_RTOL = 1e-9  # s_k below this fraction of s0 is zero: exact collinearity or coplanarity
SPREAD_RATIO = 3.0  # a plane needs s1 (spread along the 2nd axis) well above s2 (the scatter)

PLANE_MIN_POINTS = 3
# eps1, eps2. At 0.03 a flat side's edge is rounded off by about 1 % of the size (at 0.1 it was
# 3 %, and a fit to contacts on the edges grew 5-10 % too large); below it the exponents 2/eps
# make F too steep to optimise reliably.
SHAPE_BOUNDS = (0.03, 2.0)
SUPERQUADRIC_MIN_POINTS = 11  # one per parameter: 3 sizes, 2 shapes, 3 translation, 3 rotation
# Starting exponents (eps1, eps2): square-edged and ellipsoidal. Each is tried with each
# principal axis as the superquadric's z axis, because a cylinder fits only along its own axis.
DEFAULT_STARTS: tuple[tuple[float, float], ...] = ((0.3, 0.3), (1.0, 1.0))
TIE_RTOL = 1e-6  # costs this close (relative) are the same fit
# Soft-L1 loss: a residual above this (in units of the points' rms radius, about 0.1 mm off
# the surface on a hand-sized solid) counts in proportion to its size, not its square, so that
# a few contacts off the model (on a sharp edge, which no superquadric reaches exactly, or a
# stray contact) pull the fit less.
LOSS_SCALE = 0.003
MAX_EVALUATIONS = 600  # per start: good starts converge in 20-300, poor ones crawl on


class FitError(ValueError):
    """The points cannot determine the fit: too few, not finite, or degenerate."""


@dataclass(frozen=True, eq=False)
class PlaneFit:
    """A least-squares plane. Arrays are read-only; lengths in m.

    ``normal`` (3,) is a unit vector in the hemisphere of the ``up`` vector given to
    :func:`fit_plane`. ``axes`` (2, 3) holds the in-plane principal directions as rows, the
    direction of largest spread first, with ``axes[0] x axes[1] = normal``. ``extents`` (2,)
    is max - min of the points projected on each axis, and ``centre`` (3,) the point of the
    plane halfway between those extremes: the middle of a traced face. Residuals are distances
    off the plane.
    """

    centroid: Array
    normal: Array
    axes: Array
    extents: Array
    centre: Array
    rms_residual: float
    max_residual: float
    count: int

    def as_result(self) -> dict[str, Any]:
        """The fit in the criteria's format (``normal``, ``extents``), plus the rest for logs."""
        return {
            "normal": _floats(self.normal),
            "extents": _floats(self.extents),
            "centroid": _floats(self.centroid),
            "centre": _floats(self.centre),
            "axes": [_floats(a) for a in self.axes],
            "rms_residual": self.rms_residual,
            "max_residual": self.max_residual,
            "count": self.count,
        }


@dataclass(frozen=True, eq=False)
class SuperquadricFit:
    """A superquadric recovered from points. Arrays are read-only; lengths in m.

    ``size`` (3,) holds the half-sizes a1, a2, a3 along the columns of ``rotation`` (3, 3),
    the superquadric's x, y, z axes in the world frame, with a1 >= a2 and z in the upper
    hemisphere (world z >= 0). ``shape`` (2,) is (eps1, eps2): eps1 shapes the profile along
    z, eps2 the cross-section in x-y. ``centre`` (3,) is in the world frame. ``rms_residual``
    is the rms radial distance of the points off the surface (m); ``cost`` is half the sum of
    the squared residuals of Solina's objective at the fit (m^3, see :func:`fit_superquadric`).
    """

    size: Array
    shape: Array
    centre: Array
    rotation: Array
    rms_residual: float
    cost: float
    count: int

    def as_result(self) -> dict[str, Any]:
        """The fit in the criteria's format (``size``, ``shape``), plus the pose for logs."""
        return {
            "size": _floats(self.size),
            "shape": _floats(self.shape),
            "centre": _floats(self.centre),
            "rotation": [_floats(row) for row in self.rotation],
            "rms_residual": self.rms_residual,
            "cost": self.cost,
            "count": self.count,
        }


def fit_plane(points: npt.ArrayLike, up: npt.ArrayLike = (0.0, 0.0, 1.0)) -> PlaneFit:
    """Fit a plane to ``points`` (N, 3) m by SVD (total least squares).

    The normal is the direction of least spread, flipped so that ``normal @ up >= 0``.
    Raises :class:`FitError` for fewer than 3 points, non-finite values, or points that are
    collinear to within their scatter off the line (the normal would be arbitrary).
    """
    p = _points(points, PLANE_MIN_POINTS, "a plane")
    up_vec = np.asarray(up, dtype=float)
    if up_vec.shape != (3,) or not np.all(np.isfinite(up_vec)) or not np.any(up_vec):
        raise FitError(f"up must be a non-zero 3-vector, got {up!r}")
    centroid = p.mean(axis=0)
    centred = p - centroid
    _, s, vt = np.linalg.svd(centred, full_matrices=False)
    if s[1] <= max(RANK_RTOL * s[0], SPREAD_RATIO * s[2]):
        raise FitError(
            f"the {len(p)} points are collinear: their spread across the line "
            f"({_rms_mm(s[1], len(p))} rms) is not well above their scatter off a plane "
            f"({_rms_mm(s[2], len(p))} rms)"
        )
    normal = vt[2] if vt[2] @ up_vec >= 0.0 else -vt[2]
    axes = _plane_axes(centred, normal, vt[0])
    along = centred @ axes.T
    off = centred @ normal
    return PlaneFit(
        centroid=_frozen(centroid),
        normal=_frozen(normal),
        axes=_frozen(axes),
        extents=_frozen(along.max(axis=0) - along.min(axis=0)),
        centre=_frozen(centroid + axes.T @ ((along.max(axis=0) + along.min(axis=0)) / 2.0)),
        rms_residual=float(np.sqrt(np.mean(off**2))),
        max_residual=float(np.max(np.abs(off))),
        count=len(p),
    )


def _plane_axes(centred: Array, normal: Array, principal: Array) -> Array:
    """The in-plane axes (2, 3): the traces' directions when the points lie on straight
    traces (:func:`dial.haptics.lines.trace_angle`), else the principal ones; the axis of
    the larger extent first, its largest component positive, ``axes[0] x axes[1] = normal``."""
    first = _sign_fixed(principal)
    axes = np.stack([first, np.cross(normal, first)])
    angle = trace_angle(centred @ axes.T)
    if angle is None:
        return axes
    turned = np.cos(angle) * axes[0] + np.sin(angle) * axes[1]
    pair = np.stack([turned, np.cross(normal, turned)])
    spread = np.ptp(centred @ pair.T, axis=0)
    first = _sign_fixed(pair[0] if spread[0] >= spread[1] else pair[1])
    return np.stack([first, np.cross(normal, first)])


def fit_superquadric(
    points: npt.ArrayLike, starts: Sequence[tuple[float, float]] = DEFAULT_STARTS
) -> SuperquadricFit:
    """Recover a superquadric from surface points ``points`` (N, 3) m, after Solina (1990).

    In the superquadric's frame the inside-outside function is
    ``F = ((x/a1)^(2/e2) + (y/a2)^(2/e2))^(e2/e1) + (z/a3)^(2/e1)``: F = 1 on the surface,
    F < 1 inside. ``scipy.optimize.least_squares`` (trust region reflective, bounded)
    minimises the residuals ``sqrt(a1 a2 a3) (F^e1 - 1)`` over the half-sizes a1..a3 > 0, the
    exponents e1, e2 in ``SHAPE_BOUNDS``, the centre and a rotation vector, with a soft-L1
    loss (``LOSS_SCALE``): the larger residuals count by size, not by square. ``F^e1 - 1`` is
    about twice a point's relative radial distance off the surface; the volume factor makes
    the smallest superquadric that fits win, which closes sides the points do not reach (the
    bottom of an object standing on a table) at the outermost contacts.

    Each start in ``starts`` (eps1, eps2) is tried with each principal axis of the points as
    z, from the centre and half-ranges of their principal-axis bounding box, and again with
    the frame turned 45 deg about z; the fit with the lowest objective wins. Raises
    :class:`FitError` for fewer than 11 points (one per parameter), non-finite values, or
    points that span no volume (collinear or coplanar).
    """
    if not starts:
        raise ValueError("starts must name at least one (eps1, eps2) pair")
    p = _points(points, SUPERQUADRIC_MIN_POINTS, "a superquadric")
    origin, scale, q, vt = _normalised(p)
    along = q @ vt.T
    low, high = along.min(axis=0), along.max(axis=0)
    mid = vt.T @ ((low + high) / 2.0)
    half = np.maximum((high - low) / 2.0, 1e-3)
    # Sizes may grow to twice the points' span: enough for partial coverage, and it keeps a
    # side no point constrains from running away.
    size_bounds = (np.full(3, 1e-3), np.full(3, 2.0 * float(np.max(high - low))))

    best: tuple[float, float, Array, Array] | None = None
    for frame, sizes in _frames(vt, half):
        for start in starts:
            x0 = np.concatenate([sizes, start, mid, np.zeros(3)])
            robust, cost, x = _solve(q, frame, x0, size_bounds)
            # Boxes and ellipsoids fit equally well with any axis as z: a near-tie keeps the
            # earlier start, so that rounding does not decide which axis is reported as z.
            if best is None or robust < best[0] * (1.0 - TIE_RTOL):
                best = (robust, cost, x, frame)
    assert best is not None
    _, cost, x, frame = best
    size, shape, centre = x[0:3], x[3:5], x[5:8]
    rotation = frame @ Rotation.from_rotvec(x[8:11]).as_matrix()
    size, rotation = _canonical(size, rotation)
    local = (q - centre) @ rotation
    return SuperquadricFit(
        size=_frozen(size * scale),
        shape=_frozen(shape.copy()),
        centre=_frozen(origin + centre * scale),
        rotation=_frozen(rotation),
        rms_residual=float(np.sqrt(np.mean(_radial_distance(local, size, shape) ** 2)) * scale),
        cost=cost * scale**3,
        count=len(p),
    )


def _normalised(p: Array) -> tuple[Array, float, Array, Array]:
    """The points' mean, rms radius, the points in units of it about the mean (so sizes,
    centre and rotation are all ~1), and their principal axes (rows); raises
    :class:`FitError` for points that span no volume."""
    origin = p.mean(axis=0)
    scale = float(np.sqrt(np.mean(np.sum((p - origin) ** 2, axis=1))))
    q = (p - origin) / scale
    _, s, vt = np.linalg.svd(q, full_matrices=False)
    if s[2] <= RANK_RTOL * s[0]:
        raise FitError(f"the {len(p)} points span no volume: they are collinear or coplanar")
    return origin, scale, q, vt


def _frames(vt: Array, half: Array) -> list[tuple[Array, Array]]:
    """Start frames and half-sizes: each principal axis (rows of ``vt``) as z, and each also
    turned by 45 deg about z. The principal axes of a near-square cross-section lie anywhere
    in its plane, and a fit started 25 deg or more off a box's faces can end in a pinched
    shape; one of the two starts is within 22.5 deg of the faces."""
    c = s = np.sqrt(0.5)
    twist = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    frames = []
    for z_axis in (2, 1, 0):
        x_axis, y_axis = (i for i in (0, 1, 2) if i != z_axis)
        frame = np.stack([vt[x_axis], vt[y_axis], vt[z_axis]], axis=1)
        if np.linalg.det(frame) < 0.0:
            frame[:, 0] = -frame[:, 0]
        sizes = half[[x_axis, y_axis, z_axis]]
        across = float(np.hypot(sizes[0], sizes[1]) * c)
        frames += [(frame, sizes), (frame @ twist, np.array([across, across, sizes[2]]))]
    return frames


def _solve(
    q: Array, frame: Array, x0: Array, size_bounds: tuple[Array, Array]
) -> tuple[float, float, Array]:
    """One bounded robust least-squares run from ``x0`` (sizes, shapes, centre, rotation
    vector relative to ``frame``). Returns the robust objective, the plain cost (half the sum
    of squared residuals) and the parameters."""
    lower = np.concatenate([size_bounds[0], np.full(2, SHAPE_BOUNDS[0]), np.full(6, -np.inf)])
    upper = np.concatenate([size_bounds[1], np.full(2, SHAPE_BOUNDS[1]), np.full(6, np.inf)])
    x0 = np.clip(x0, lower, upper)

    def residuals(x: Array) -> Array:
        rotation = frame @ Rotation.from_rotvec(x[8:11]).as_matrix()
        local = (q - x[5:8]) @ rotation
        size, shape = x[0:3], x[3:5]
        inside_outside = np.exp(shape[0] * _log_f(local, size, shape))  # F^e1
        return np.asarray(np.sqrt(np.prod(size)) * (inside_outside - 1.0))

    done = least_squares(
        residuals,
        x0,
        bounds=(lower, upper),
        x_scale="jac",
        loss="soft_l1",
        f_scale=LOSS_SCALE,
        max_nfev=MAX_EVALUATIONS,
    )
    cost = 0.5 * float(np.sum(done.fun**2))
    return float(done.cost), cost, np.asarray(done.x, dtype=float)


def _log_f(local: Array, size: Array, shape: Array) -> Array:
    """log F of the inside-outside function at ``local`` (N, 3) points, by log-sum-exp: F
    itself overflows for far points when an exponent 2/eps is large."""
    e1, e2 = shape
    log_ratio = np.log(np.maximum(np.abs(local), 1e-12) / size)
    section = np.logaddexp(2.0 / e2 * log_ratio[:, 0], 2.0 / e2 * log_ratio[:, 1])
    return np.asarray(np.logaddexp(e2 / e1 * section, 2.0 / e1 * log_ratio[:, 2]))


def _radial_distance(local: Array, size: Array, shape: Array) -> Array:
    """Distance (in ``local``'s units) from each point to the surface along the ray from the
    centre: F is homogeneous of degree 2/e1, so the ray meets the surface at F^(-e1/2) r."""
    radius = np.linalg.norm(local, axis=1)
    return np.asarray(radius * np.abs(1.0 - np.exp(-shape[0] / 2.0 * _log_f(local, size, shape))))


def _canonical(size: Array, rotation: Array) -> tuple[Array, Array]:
    """The same superquadric with a1 >= a2 and its z axis in the upper world hemisphere.

    x and y are interchangeable, and any two axes may flip sign together, without changing
    the solid; this removes those ambiguities from the reported pose."""
    size, rotation = size.copy(), rotation.copy()
    if size[1] > size[0]:
        size[[0, 1]] = size[[1, 0]]
        rotation[:, [0, 1]] = rotation[:, [1, 0]]
        rotation[:, 2] = -rotation[:, 2]
    if rotation[2, 2] < 0.0:
        rotation[:, [0, 2]] = -rotation[:, [0, 2]]
    return size, rotation


def _points(points: npt.ArrayLike, needed: int, what: str) -> Array:
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise FitError(f"points must be an (N, 3) array, got shape {p.shape}")
    if len(p) < needed:
        raise FitError(f"{what} needs at least {needed} points, got {len(p)}")
    if not np.all(np.isfinite(p)):
        raise FitError(f"{what} needs finite points; some of the {len(p)} are NaN or inf")
    return p


def _sign_fixed(v: Array) -> Array:
    """``v`` or ``-v``, whichever has its largest-magnitude component positive."""
    return v if v[np.argmax(np.abs(v))] >= 0.0 else -v


def _rms_mm(singular: float, n: int) -> str:
    return f"{singular / np.sqrt(n) * 1000.0:.3g} mm"


def _frozen(a: Array) -> Array:
    out = np.array(a, dtype=float)
    out.flags.writeable = False
    return out


def _floats(a: Array) -> list[float]:
    return [float(v) for v in a]
