"""Phantoms: where the tissue surface is and how stiff and viscous it is.

A :class:`Phantom` answers, for points (x, y) in the robot base frame, the
tissue surface height z(x, y), its gradient, and the Hunt-Crossley
parameters kappa(x, y), lambda(x, y) for one exponent beta. Two kinds:

- :class:`GridPhantom`: a map on a regular grid, e.g. the paper's measured
  GP map (``phantom_map/``). Bilinear lookup (as the real controller's
  logs show) or nearest. Outside the grid a query is clamped to the nearest grid
  edge: values extend constantly and the gradient across the edge is zero.
- :class:`SyntheticChestPhantom`: an analytic chest (torso, curvature,
  shoulder rise, ribs as stiff bands, one rib under muscle), the embedded
  default when the measured data is absent. Every parameter lives in
  :class:`SyntheticChestParams`. Outside its footprint it clamps likewise.

All methods are vectorised: x and y broadcast against each other.
"""

from vic_drake.tissue.phantom.base import Phantom, TissueSample
from vic_drake.tissue.phantom.grid import GridPhantom
from vic_drake.tissue.phantom.kinds import PHANTOM_KINDS, load_phantom
from vic_drake.tissue.phantom.point_lookup import PointLookup
from vic_drake.tissue.phantom.synthetic_chest import (
    SyntheticChestParams,
    SyntheticChestPhantom,
)

__all__ = [
    "GridPhantom",
    "PHANTOM_KINDS",
    "Phantom",
    "PointLookup",
    "SyntheticChestParams",
    "SyntheticChestPhantom",
    "TissueSample",
    "load_phantom",
]
