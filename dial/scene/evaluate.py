"""Evaluate a world file's success criteria on the final MuJoCo state and the run's fits.

``results`` maps a point-set name (the ``SET`` of ``fit_plane SET`` / ``fit_superquadric
SET``) to that fit's result: a plane fit has ``normal`` (3,) and ``extents`` (2,) in m, the
extents of the traced points along the plane's two principal axes; a superquadric fit has
``size`` (3,) half-sizes in m and ``shape`` (2,), the exponents (eps1, eps2) of Barr and
Solina: eps1 shapes the profile along the superquadric's z axis, eps2 its cross-section.
"""

from __future__ import annotations

import fnmatch
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from dial.scene.criteria import (
    Above,
    Criterion,
    FingerContacts,
    FractionInRegion,
    PlaneFit,
    SuperquadricFit,
    Upright,
)

Results = Mapping[str, Mapping[str, Any]]
SQUARE_BELOW = 0.5  # a superquadric exponent below this is a flat side, above it round


def evaluate(
    criteria: Iterable[Criterion], model: mujoco.MjModel, data: mujoco.MjData, results: Results
) -> dict[str, bool]:
    """Criterion name -> whether it holds. ``data`` must be current (after a step or forward)."""
    return {c.name: measure(c, model, data, results)[0] for c in criteria}


def measure(
    criterion: Criterion, model: mujoco.MjModel, data: mujoco.MjData, results: Results
) -> tuple[bool, str]:
    """Whether ``criterion`` holds, and what was measured, for the run summary."""
    return _MEASURES[type(criterion)](criterion, model, data, results)


@dataclass(frozen=True)
class Reading:
    """What a criterion measures in the current state, as a number to plot over a run:
    ``quantity`` of the body ``subject`` (``height`` of ``lightbulb_bulb``) in ``unit``."""

    subject: str
    quantity: str
    value: float
    unit: str


def reading(criterion: Criterion, model: mujoco.MjModel, data: mujoco.MjData) -> Reading | None:
    """The criterion's measured quantity now; None for those that judge a fit's result."""
    read = reader(criterion, model)
    return None if read is None else read(data)


def reader(
    criterion: Criterion, model: mujoco.MjModel
) -> Callable[[mujoco.MjData], Reading] | None:
    """:func:`reading` with the criterion's bodies looked up once, to sample a run often."""
    if isinstance(criterion, FractionInRegion):
        bodies = _region_bodies(criterion, model)
        site = model.site(criterion.region)
        cup = model.body(model.site_bodyid[site.id]).name
        return lambda d: Reading(cup, "contents", _inside(criterion, model, d, bodies)[0], "bodies")
    read = _READINGS.get(type(criterion))
    return None if read is None else lambda d: read(criterion, model, d)


def _region_bodies(c: FractionInRegion, m: mujoco.MjModel) -> list[int]:
    bodies = [i for i in range(m.nbody) if fnmatch.fnmatchcase(m.body(i).name, c.bodies)]
    if not bodies:
        raise ValueError(f"criterion {c.name}: no body matches '{c.bodies}'")
    return bodies


def _inside(
    c: FractionInRegion, m: mujoco.MjModel, d: mujoco.MjData, bodies: list[int] | None = None
) -> tuple[int, int]:
    """How many of the matching bodies lie in the region, and how many match."""
    bodies = _region_bodies(c, m) if bodies is None else bodies
    site = m.site(c.region)
    if site.type[0] != mujoco.mjtGeom.mjGEOM_BOX:
        raise ValueError(f"criterion {c.name}: region site '{c.region}' must be a box")
    local = (d.xpos[bodies] - d.site_xpos[site.id]) @ d.site_xmat[site.id].reshape(3, 3)
    return int(np.all(np.abs(local) <= site.size, axis=1).sum()), len(bodies)


def _fraction_in_region(
    c: FractionInRegion, m: mujoco.MjModel, d: mujoco.MjData, _: Results
) -> tuple[bool, str]:
    inside, total = _inside(c, m, d)
    return inside / total >= c.min, f"{inside}/{total} in {c.region} (min {c.min:.0%})"


def _tilt(c: Upright, m: mujoco.MjModel, d: mujoco.MjData) -> float:
    """The object's tilt from upright, rad."""
    z = d.xmat[m.body(c.body).id].reshape(3, 3)[:, 2]
    return math.acos(float(np.clip(z[2], -1.0, 1.0)))


def _upright(c: Upright, m: mujoco.MjModel, d: mujoco.MjData, _: Results) -> tuple[bool, str]:
    tilt = _tilt(c, m, d)
    return tilt <= c.max_tilt, f"tilt {math.degrees(tilt):.1f} deg"


def _height(c: Above, m: mujoco.MjModel, d: mujoco.MjData) -> float:
    """The object's origin above the site, m."""
    return float(d.xpos[m.body(c.body).id, 2] - d.site_xpos[m.site(c.site).id, 2])


def _above(c: Above, m: mujoco.MjModel, d: mujoco.MjData, _: Results) -> tuple[bool, str]:
    height = _height(c, m, d)
    return height >= c.min_height, f"{height * 1000:.1f} mm above {c.site}"


def _touching(
    c: FingerContacts, m: mujoco.MjModel, d: mujoco.MjData, force: bool = False
) -> tuple[set[str], float]:
    """The finger prefixes whose bodies touch the object; with ``force``, also the normal
    force they press it with in all (N; else 0)."""
    target = m.body(c.body).id
    bodies = m.geom_bodyid[d.contact.geom[: d.ncon]]  # (ncon, 2): one read of the contacts
    touching: set[str] = set()
    total = 0.0
    wrench = np.zeros(6)
    for i in np.flatnonzero((bodies == target).any(axis=1)):
        b1, b2 = bodies[i]
        other = m.body(int(b2 if b1 == target else b1)).name
        fingers = [p for p in c.fingers if other.startswith(p)]
        if fingers:
            touching.update(fingers)
            if force:
                mujoco.mj_contactForce(m, d, int(i), wrench)
                total += abs(float(wrench[0]))  # the normal component, in the contact frame
    return touching, total


def _finger_contacts(
    c: FingerContacts, m: mujoco.MjModel, d: mujoco.MjData, _: Results
) -> tuple[bool, str]:
    touching, force = _touching(c, m, d, force=not math.isinf(c.max_force))
    names = ", ".join(sorted(touching)) or "none"
    detail = f"{len(touching)} fingers touch ({names})"
    if math.isinf(c.max_force):
        return len(touching) >= c.min, detail
    held = len(touching) >= c.min and force <= c.max_force
    return held, f"{detail} with {force:.1f} N (max {c.max_force:g} N)"


def _plane_fit(c: PlaneFit, m: mujoco.MjModel, d: mujoco.MjData, r: Results) -> tuple[bool, str]:
    fit = r.get(c.set)
    if fit is None:
        return False, f"no plane fit of set '{c.set}'"
    geom = _solid(m, c.body, mujoco.mjtGeom.mjGEOM_BOX)
    axis = "xyz".index(c.face[1])
    normal = d.geom_xmat[geom.id].reshape(3, 3)[:, axis]
    fitted = _vector(fit, "normal", 3)
    # A fitted plane's normal may point either way.
    cos = abs(float(normal @ fitted)) / float(np.linalg.norm(fitted))
    angle = math.acos(min(cos, 1.0))
    true_ext = np.sort(2.0 * np.delete(geom.size, axis))[::-1]
    fit_ext = np.sort(_vector(fit, "extents", 2))[::-1]
    err = float(np.max(np.abs(fit_ext - true_ext)))
    ok = angle <= c.normal_tol and err <= c.extent_tol
    return ok, f"normal off by {math.degrees(angle):.2f} deg, extents off by {err * 1000:.1f} mm"


def _superquadric_fit(
    c: SuperquadricFit, m: mujoco.MjModel, d: mujoco.MjData, r: Results
) -> tuple[bool, str]:
    fit = r.get(c.set)
    if fit is None:
        return False, f"no superquadric fit of set '{c.set}'"
    geom = _solid(m, c.body, None)
    true_size, true_shape = _true_superquadric(geom)
    size = np.sort(_vector(fit, "size", 3))
    rel = float(np.max(np.abs(size - np.sort(true_size)) / np.sort(true_size)))
    shape = shape_class(*_vector(fit, "shape", 2))
    ok = rel <= c.size_tol and shape == true_shape
    return ok, f"size off by {rel:.1%}, shape {shape} (true {true_shape})"


def shape_class(eps1: float, eps2: float) -> str:
    """Name the solid that superquadric exponents describe: box, cylinder, rounded or other."""
    flat_profile, flat_section = eps1 < SQUARE_BELOW, eps2 < SQUARE_BELOW
    if flat_profile and flat_section:
        return "box"
    if flat_profile:
        return "cylinder"
    return "other" if flat_section else "rounded"


def _true_superquadric(geom: Any) -> tuple[np.ndarray, str]:
    kind, size = geom.type[0], geom.size
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        return size.copy(), "box"
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return np.array([size[0], size[0], size[1]]), "cylinder"
    if kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        return size.copy(), "rounded"
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        return np.full(3, size[0]), "rounded"
    raise ValueError(f"geom '{geom.name}' has no superquadric equivalent")


def _solid(m: mujoco.MjModel, body: str, kind: int | None) -> Any:
    """The geom that is the object's solid: by convention it is named like its body."""
    geom = m.geom(body)
    if kind is not None and geom.type[0] != kind:
        raise ValueError(f"geom '{body}' must be a box for a plane fit")
    return geom


def _vector(fit: Mapping[str, Any], key: str, n: int) -> np.ndarray:
    value = np.asarray(fit.get(key, ()), dtype=float)
    if value.shape != (n,) or not np.all(np.isfinite(value)):
        raise ValueError(f"fit result '{key}' must be {n} finite numbers, got {fit.get(key)!r}")
    return value


_READINGS: dict[type, Callable[[Any, mujoco.MjModel, mujoco.MjData], Reading]] = {
    Upright: lambda c, m, d: Reading(c.body, "tilt", math.degrees(_tilt(c, m, d)), "deg"),
    Above: lambda c, m, d: Reading(c.body, "height", 1000 * _height(c, m, d), "mm"),
    FingerContacts: lambda c, m, d: Reading(c.body, "touch", len(_touching(c, m, d)[0]), "fingers"),
}

_MEASURES: dict[type, Callable[[Any, mujoco.MjModel, mujoco.MjData, Results], tuple[bool, str]]]
_MEASURES = {
    FractionInRegion: _fraction_in_region,
    Upright: _upright,
    Above: _above,
    FingerContacts: _finger_contacts,
    PlaneFit: _plane_fit,
    SuperquadricFit: _superquadric_fit,
}
