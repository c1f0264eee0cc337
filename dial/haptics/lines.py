"""The in-plane axes of traced contacts: the directions of the traces themselves.

Surface exploration (Allen et al. 1990, section VI-B) traces a face in straight lines: out
and back along one direction, then along the perpendicular one. The principal directions of
such a cross turn away from the traces when its arms are lopsided (a first contact near a
corner leaves one arm a few points long, and the points then have a spread that mixes both
directions): 12-20 deg with a block 20 mm from where it was believed, which shortens both
extents by 5-15 mm. The traces' own directions do not depend on where along them the points
lie, so here the points are split into straight lines and the axes are the lines' mean
direction, each line counted modulo 90 deg (a trace and the one perpendicular to it agree)
and weighted by its points.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

LINE_TOL = 0.0015  # m: a point this close to a line lies on it (a trace drifts ~1 deg)
LINE_MIN_POINTS = 3  # a line of fewer points is not a trace
COVERED = 0.9  # the lines must hold this fraction of the points, else they are not traces
MAX_LINES = 8
SCAN_STEP_DEG = 0.5  # the directions tried for the densest line, refined by least squares


def trace_angle(flat: Array) -> float | None:
    """The direction (rad, in [0, pi/2)) of the traces through ``flat`` (N, 2) in-plane
    points, modulo 90 deg; None when the points are not at least two straight lines that
    hold ``COVERED`` of them (one trace, or scattered points)."""
    left = np.asarray(flat, dtype=np.float64)
    lines: list[tuple[float, int]] = []  # (angle, points)
    while len(left) >= LINE_MIN_POINTS and len(lines) < MAX_LINES:
        angle, on = _densest_line(left)
        if int(on.sum()) < LINE_MIN_POINTS:
            break
        lines.append((angle, int(on.sum())))
        left = left[~on]
    held = sum(n for _, n in lines)
    if len(lines) < 2 or held < COVERED * len(flat):
        return None
    weights = np.array([n for _, n in lines], dtype=np.float64)
    quad = 4.0 * np.array([a for a, _ in lines])  # period 90 deg -> 360 deg
    mean = float(np.arctan2(weights @ np.sin(quad), weights @ np.cos(quad))) / 4.0
    return mean % (np.pi / 2.0)


def _densest_line(points: Array) -> tuple[float, npt.NDArray[np.bool_]]:
    """The straight line through the most points (``LINE_TOL``): its direction (rad) after
    a least-squares refit to those points, and which points lie on it."""
    best: tuple[int, float, float, float] | None = None  # (count, -spread, angle, offset)
    for angle in np.radians(np.arange(0.0, 180.0, SCAN_STEP_DEG)):
        normal = np.array([-np.sin(angle), np.cos(angle)])
        offsets = np.sort(points @ normal)
        # The widest run of offsets within 2 LINE_TOL: for each start, the end of its window.
        ends = np.searchsorted(offsets, offsets + 2.0 * LINE_TOL, side="right")
        counts = ends - np.arange(len(offsets))
        i = int(np.argmax(counts))
        window = offsets[i : ends[i]]
        key = (int(counts[i]), -float(np.ptp(window)), float(angle), float(window.mean()))
        if best is None or key[:2] > best[:2]:
            best = key
    assert best is not None
    _, _, angle, offset = best
    normal = np.array([-np.sin(angle), np.cos(angle)])
    on = np.abs(points @ normal - offset) <= LINE_TOL
    centred = points[on] - points[on].mean(axis=0)
    direction = np.linalg.svd(centred, full_matrices=False)[2][0]
    refined = float(np.arctan2(direction[1], direction[0])) % np.pi
    normal = np.array([-np.sin(refined), np.cos(refined)])
    on = np.abs((points - points[on].mean(axis=0)) @ normal) <= LINE_TOL
    return refined, on
