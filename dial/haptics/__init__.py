"""Haptic perception (Allen et al. 1990, section VI): fits to fingertip contact points.

``fit_plane`` serves surface exploration, ``fit_superquadric`` grasping by containment. Pure
numpy and scipy; the instructions that collect the points live elsewhere.
"""

from dial.haptics.fit import (
    FitError,
    PlaneFit,
    SuperquadricFit,
    fit_plane,
    fit_superquadric,
)

__all__ = ["FitError", "PlaneFit", "SuperquadricFit", "fit_plane", "fit_superquadric"]
