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


def _fraction_in_region(
    c: FractionInRegion, m: mujoco.MjModel, d: mujoco.MjData, _: Results
) -> tuple[bool, str]:
    bodies = [i for i in range(m.nbody) if fnmatch.fnmatchcase(m.body(i).name, c.bodies)]
    if not bodies:
        raise ValueError(f"criterion {c.name}: no body matches '{c.bodies}'")
    site = m.site(c.region)
    if site.type[0] != mujoco.mjtGeom.mjGEOM_BOX:
        raise ValueError(f"criterion {c.name}: region site '{c.region}' must be a box")
    local = (d.xpos[bodies] - d.site_xpos[site.id]) @ d.site_xmat[site.id].reshape(3, 3)
    inside = int(np.all(np.abs(local) <= site.size, axis=1).sum())
    fraction = inside / len(bodies)
    return fraction >= c.min, f"{inside}/{len(bodies)} in {c.region} (min {c.min:.0%})"


def _upright(c: Upright, m: mujoco.MjModel, d: mujoco.MjData, _: Results) -> tuple[bool, str]:
    z = d.xmat[m.body(c.body).id].reshape(3, 3)[:, 2]
    tilt = math.acos(float(np.clip(z[2], -1.0, 1.0)))
    return tilt <= c.max_tilt, f"tilt {math.degrees(tilt):.1f} deg"


def _above(c: Above, m: mujoco.MjModel, d: mujoco.MjData, _: Results) -> tuple[bool, str]:
    height = float(d.xpos[m.body(c.body).id, 2] - d.site_xpos[m.site(c.site).id, 2])
    return height >= c.min_height, f"{height * 1000:.1f} mm above {c.site}"


def _finger_contacts(
    c: FingerContacts, m: mujoco.MjModel, d: mujoco.MjData, _: Results
) -> tuple[bool, str]:
    target = m.body(c.body).id
    touching: set[str] = set()
    force = 0.0
    wrench = np.zeros(6)
    for i, contact in enumerate(d.contact[: d.ncon]):
        b1, b2 = m.geom_bodyid[contact.geom1], m.geom_bodyid[contact.geom2]
        if target not in (b1, b2):
            continue
        other = m.body(b2 if b1 == target else b1).name
        fingers = [p for p in c.fingers if other.startswith(p)]
        if fingers:
            touching.update(fingers)
            mujoco.mj_contactForce(m, d, i, wrench)
            force += abs(float(wrench[0]))  # the normal component, in the contact frame
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


_MEASURES: dict[type, Callable[[Any, mujoco.MjModel, mujoco.MjData, Results], tuple[bool, str]]]
_MEASURES = {
    FractionInRegion: _fraction_in_region,
    Upright: _upright,
    Above: _above,
    FingerContacts: _finger_contacts,
    PlaneFit: _plane_fit,
    SuperquadricFit: _superquadric_fit,
}
