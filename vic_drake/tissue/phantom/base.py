"""The phantom interface: tissue surface, slope, kappa and lambda over (x, y).

A :class:`Phantom` answers, for points (x, y) in the robot base frame, the
tissue surface height z(x, y), its gradient, and the Hunt-Crossley
parameters kappa(x, y), lambda(x, y) for one exponent beta, as a
:class:`TissueSample`. All methods are vectorised: x and y broadcast against
each other.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import OrderedDict
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.paper import BEST_BETA

if TYPE_CHECKING:
    from vic_drake.tissue.phantom.point_lookup import PointLookup


#: Point lookups shared by phantoms with equal :meth:`Phantom.content_key`,
#: most recently used last; at most :data:`SHARED_LOOKUPS_MAX` are kept.
_SHARED_LOOKUPS: OrderedDict = OrderedDict()
SHARED_LOOKUPS_MAX = 2


def _shared_point_lookup(key, build) -> PointLookup:
    """The point lookup of ``key``: the process's shared one, else ``build()``."""
    lookup = _SHARED_LOOKUPS.get(key)
    if lookup is None:
        lookup = _SHARED_LOOKUPS[key] = build()
        while len(_SHARED_LOOKUPS) > SHARED_LOOKUPS_MAX:
            _SHARED_LOOKUPS.popitem(last=False)
    else:
        _SHARED_LOOKUPS.move_to_end(key)
    return lookup


@dataclass(frozen=True)
class TissueSample:
    """Tissue at query points (arrays of the broadcast query shape).

    Attributes:
        surface_z_m: tissue surface height, m (base frame).
        dz_dx: surface slope along x (dimensionless).
        dz_dy: surface slope along y (dimensionless).
        kappa: Hunt-Crossley elasticity, N/m^beta.
        lam: Hunt-Crossley viscosity, N s/m^(beta+1).
    """

    surface_z_m: np.ndarray
    dz_dx: np.ndarray
    dz_dy: np.ndarray
    kappa: np.ndarray
    lam: np.ndarray


class Phantom(ABC):
    """A tissue map: surface height, slope, kappa and lambda over (x, y)."""

    #: Short name used in logs and reports.
    name: str = "phantom"
    #: Hunt-Crossley exponent the map's kappa and lambda belong to.
    beta: float = BEST_BETA

    @property
    @abstractmethod
    def bounds(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the region where the map is defined, m."""

    @abstractmethod
    def sample(self, x, y) -> TissueSample:
        """The tissue at points (x, y), m."""

    def surface_z(self, x, y) -> np.ndarray:
        return self.sample(x, y).surface_z_m

    def surface_gradient(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        s = self.sample(x, y)
        return s.dz_dx, s.dz_dy

    def kappa(self, x, y) -> np.ndarray:
        return self.sample(x, y).kappa

    def lam(self, x, y) -> np.ndarray:
        return self.sample(x, y).lam

    def contains(self, x, y) -> np.ndarray:
        x_min, x_max, y_min, y_max = self.bounds
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        return (x >= x_min) & (x <= x_max) & (y >= y_min) & (y <= y_max)

    def point_lookup(self, resolution_m: float = 0.0005) -> PointLookup:
        """A fast scalar lookup for per-tick queries (built once, then cached).

        See :class:`PointLookup`: exact for a GridPhantom, a bilinear
        rasterization at ``resolution_m`` for any other phantom.
        """
        # Import cycle: grid.py and point_lookup.py import this module.
        from vic_drake.tissue.phantom.grid import GridPhantom
        from vic_drake.tissue.phantom.point_lookup import PointLookup

        cache = self.__dict__.get("_point_lookups")
        if cache is None or cache["owner"] != id(self):
            # First call, or a (shallow) copy of another phantom: own cache.
            cache = self.__dict__["_point_lookups"] = {"owner": id(self)}
        if isinstance(self, GridPhantom):
            key = ("grid", self.lookup)
        else:
            key = ("raster", float(resolution_m))
        if key not in cache:
            content = self.content_key()
            if content is None:
                cache[key] = PointLookup(self, resolution_m=resolution_m)
            else:
                cache[key] = _shared_point_lookup(
                    (content, key),
                    lambda: PointLookup(self, resolution_m=resolution_m),
                )
        return cache[key]

    def __getstate__(self) -> dict:
        # The point lookups are a cache (40 MB for the synthetic chest at
        # 0.5 mm), rebuilt where needed: a pickled phantom (to a Dask
        # worker) leaves them behind.
        state = self.__dict__.copy()
        state.pop("_point_lookups", None)
        return state

    def content_key(self):
        """A hashable key that is equal for phantoms that answer every query
        alike (their point lookups are then built once per process and
        shared), or None: this phantom's lookups are its own."""
        return None

    def rasterize(self, resolution_m: float, bounds=None):
        """Samples the map on a regular grid.

        Returns:
            (xs, ys, sample): axes of shapes (nx,), (ny,) and a TissueSample
            of arrays shaped (nx, ny), indexed [ix, iy].
        """
        if not resolution_m > 0:
            raise VicDrakeError(f"resolution_m must be > 0, got {resolution_m!r}")
        x_min, x_max, y_min, y_max = bounds or self.bounds
        nx = int(np.floor((x_max - x_min) / resolution_m + 1e-9)) + 1
        ny = int(np.floor((y_max - y_min) / resolution_m + 1e-9)) + 1
        xs = x_min + resolution_m * np.arange(nx)
        ys = y_min + resolution_m * np.arange(ny)
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        return xs, ys, self.sample(X, Y)
