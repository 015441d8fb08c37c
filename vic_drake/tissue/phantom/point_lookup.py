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
        # The five values at each node, interleaved: one tuple per corner.
        self._nodes = [list(zip(*(g[i] for g in self._grids), strict=True))
                       for i in range(len(self._xs))]  # fmt: skip
        self.bounds = (self._xs[0], self._xs[-1], self._ys[0], self._ys[-1])

    def __call__(self, x, y) -> tuple[float, float, float, float, float]:
        # The cell and weights on each axis, clamped (this runs several times
        # a tick: inlined).
        xs, ys = self._xs, self._ys
        x, y = float(x), float(y)
        in_x = xs[0] <= x <= xs[-1]
        xc = min(max(x, xs[0]), xs[-1])
        i = min(max(bisect.bisect_right(xs, xc), 1), len(xs) - 1) - 1
        wx = (xc - xs[i]) / (xs[i + 1] - xs[i])
        in_y = ys[0] <= y <= ys[-1]
        yc = min(max(y, ys[0]), ys[-1])
        j = min(max(bisect.bisect_right(ys, yc), 1), len(ys) - 1) - 1
        wy = (yc - ys[j]) / (ys[j + 1] - ys[j])
        if self.nearest:
            # Half to even, as np.rint in GridPhantom.sample.
            i, j = round(i + wx), round(j + wy)
            z, gx, gy, kappa, lam = (g[i][j] for g in self._grids)
        else:
            w00, w10 = (1 - wx) * (1 - wy), wx * (1 - wy)
            w01, w11 = (1 - wx) * wy, wx * wy
            row0, row1 = self._nodes[i], self._nodes[i + 1]
            z00, gx00, gy00, k00, l00 = row0[j]
            z10, gx10, gy10, k10, l10 = row1[j]
            z01, gx01, gy01, k01, l01 = row0[j + 1]
            z11, gx11, gy11, k11, l11 = row1[j + 1]
            z = w00 * z00 + w10 * z10 + w01 * z01 + w11 * z11
            gx = w00 * gx00 + w10 * gx10 + w01 * gx01 + w11 * gx11
            gy = w00 * gy00 + w10 * gy10 + w01 * gy01 + w11 * gy11
            kappa = w00 * k00 + w10 * k10 + w01 * k01 + w11 * k11
            lam = w00 * l00 + w10 * l10 + w01 * l01 + w11 * l11
        return z, (gx if in_x else 0.0), (gy if in_y else 0.0), kappa, lam

    def sample(self, x, y) -> TissueSample:
        return TissueSample(*self(x, y))
