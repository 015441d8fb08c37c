"""Fast scalar lookup of a phantom at one point, for the per-tick query."""

from __future__ import annotations

import bisect

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom.base import Phantom, TissueSample
from vic_drake.tissue.phantom.grid import GridPhantom


class PointLookup:
    """Fast scalar lookup of a phantom at one point (the per-tick query).

    ``Phantom.sample`` is vectorised numpy, slow for a single point against
    a 2 ms control tick. This answers the same query with plain Python floats
    (docs/decisions.md, "Point lookup for the per-tick query"):

    - a :class:`GridPhantom` is used as is (its grids, gradient grids and
      lookup mode), so the result equals its ``sample`` to rounding;
    - any other phantom is rasterized once at ``resolution_m`` over its
      bounds (surface, gradient, kappa, lambda at the nodes, bilinear in
      between).

    Queries outside the grid clamp to its edge with zero gradient across it,
    as the phantoms do. Calling it returns the tuple
    ``(surface_z_m, dz_dx, dz_dy, kappa, lam)``; :meth:`sample` wraps the same
    floats in a :class:`TissueSample`.
    """

    def __init__(self, phantom: Phantom, *, resolution_m: float = 0.0005):
        if not (np.isfinite(resolution_m) and resolution_m > 0):
            raise VicDrakeError(f"resolution_m must be > 0, got {resolution_m!r}")
        self.beta = float(phantom.beta)
        self.name = getattr(phantom, "name", "phantom")
        if isinstance(phantom, GridPhantom):
            xs, ys = phantom.x_m, phantom.y_m
            grids = (phantom.surface_m, phantom.dz_dx_grid, phantom.dz_dy_grid,
                     phantom.kappa_grid, phantom.lam_grid)  # fmt: skip
            self.nearest = phantom.lookup == "nearest"
        else:
            xs, ys, smp = phantom.rasterize(resolution_m)
            grids = (smp.surface_z_m, smp.dz_dx, smp.dz_dy, smp.kappa, smp.lam)
            self.nearest = False
        self._xs = [float(v) for v in xs]
        self._ys = [float(v) for v in ys]
        self._grids = [np.asarray(g, float).tolist() for g in grids]
        self.bounds = (self._xs[0], self._xs[-1], self._ys[0], self._ys[-1])

    @staticmethod
    def _axis(axis, q):
        """(i0, w1, inside) of q on an increasing axis, clamped."""
        inside = axis[0] <= q <= axis[-1]
        qc = min(max(q, axis[0]), axis[-1])
        i1 = min(max(bisect.bisect_right(axis, qc), 1), len(axis) - 1)
        i0 = i1 - 1
        return i0, (qc - axis[i0]) / (axis[i1] - axis[i0]), inside

    def __call__(self, x, y) -> tuple[float, float, float, float, float]:
        i, wx, in_x = self._axis(self._xs, float(x))
        j, wy, in_y = self._axis(self._ys, float(y))
        if self.nearest:
            # Half to even, as np.rint in GridPhantom.sample.
            i, j = round(i + wx), round(j + wy)
            z, gx, gy, kappa, lam = (g[i][j] for g in self._grids)
        else:
            w00, w10 = (1 - wx) * (1 - wy), wx * (1 - wy)
            w01, w11 = (1 - wx) * wy, wx * wy
            z, gx, gy, kappa, lam = (
                w00 * g[i][j] + w10 * g[i + 1][j] + w01 * g[i][j + 1]
                + w11 * g[i + 1][j + 1]
                for g in self._grids
            )  # fmt: skip
        return z, (gx if in_x else 0.0), (gy if in_y else 0.0), kappa, lam

    def sample(self, x, y) -> TissueSample:
        return TissueSample(*self(x, y))
