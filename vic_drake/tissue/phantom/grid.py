"""A phantom given on a regular (x, y) grid, such as the paper's measured GP map.

Bilinear lookup (as the real controller's logs show) or nearest. Outside the grid a
query is clamped to the nearest grid edge: values extend constantly and the
gradient across the edge is zero.
"""

from __future__ import annotations

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.paper import BEST_BETA
from vic_drake.tissue.phantom.base import Phantom, TissueSample


def _axis_weights(axis: np.ndarray, q: np.ndarray):
    """Clamped bilinear weights along one axis: (i0, i1, w1, inside)."""
    qc = np.clip(q, axis[0], axis[-1])
    i1 = np.clip(np.searchsorted(axis, qc, side="right"), 1, axis.size - 1)
    i0 = i1 - 1
    w1 = (qc - axis[i0]) / (axis[i1] - axis[i0])
    inside = (q >= axis[0]) & (q <= axis[-1])
    return i0, i1, w1, inside


class GridPhantom(Phantom):
    """A phantom given on a regular (x, y) grid, such as the measured GP map.

    Args:
        x_m, y_m: increasing grid axes (nx,), (ny,).
        z_m: (nx, ny) surface height as stored in the map.
        kappa, lam: (nx, ny) Hunt-Crossley parameters.
        beta: their exponent.
        surface_offset_m: added to z_m to give the tissue surface (the real
            controller used +0.0025 m on the measured map).
        lookup: "bilinear" (default; what the real controller's logs show) or
            "nearest".
        name: label.
    """

    def __init__(
        self,
        *,
        x_m,
        y_m,
        z_m,
        kappa,
        lam,
        beta: float = BEST_BETA,
        surface_offset_m: float = 0.0,
        lookup: str = "bilinear",
        name: str = "grid",
    ):
        self.x_m = np.asarray(x_m, float)
        self.y_m = np.asarray(y_m, float)
        shape = (self.x_m.size, self.y_m.size)
        if self.x_m.size < 2 or self.y_m.size < 2:
            raise VicDrakeError("GridPhantom needs at least 2 points along x and y")
        if np.any(np.diff(self.x_m) <= 0) or np.any(np.diff(self.y_m) <= 0):
            raise VicDrakeError(
                "GridPhantom axes x_m and y_m must be strictly increasing"
            )
        arrays = {}
        for key, value in (("z_m", z_m), ("kappa", kappa), ("lam", lam)):
            a = np.asarray(value, float)
            if a.shape != shape:
                raise VicDrakeError(
                    f"GridPhantom {key} has shape {a.shape}; expected {shape}"
                )
            if not np.all(np.isfinite(a)):
                raise VicDrakeError(f"GridPhantom {key} has non-finite values")
            arrays[key] = a
        if lookup not in ("bilinear", "nearest"):
            raise VicDrakeError(
                f"lookup must be 'bilinear' or 'nearest', got {lookup!r}"
            )
        if not beta > 0:
            raise VicDrakeError(f"beta must be > 0, got {beta!r}")
        self.surface_m = arrays["z_m"] + float(surface_offset_m)
        self.kappa_grid = arrays["kappa"]
        self.lam_grid = arrays["lam"]
        self.dz_dx_grid, self.dz_dy_grid = np.gradient(
            self.surface_m, self.x_m, self.y_m
        )
        self.beta = float(beta)
        self.surface_offset_m = float(surface_offset_m)
        self.lookup = lookup
        self.name = name

    @classmethod
    def from_map_data(cls, data, *, lookup: str = "bilinear") -> GridPhantom:
        """From :class:`vic_drake.realdata.PhantomMapData`."""
        return cls(
            x_m=data.x_m,
            y_m=data.y_m,
            z_m=data.z_m,
            kappa=data.kappa,
            lam=data.lam,
            beta=data.beta,
            surface_offset_m=data.surface_offset_m,
            lookup=lookup,
            name="measured",
        )

    @classmethod
    def from_data_dir(cls, data_dir=None, *, lookup: str = "bilinear") -> GridPhantom:
        """Loads ``<data_dir>/phantom_map`` (see vic_drake.paths for the default)."""
        # Optional heavy dependency: realdata imports pandas, which the numpy
        # tissue layer needs only to read the measured map.
        from vic_drake.paths import require_data_dir
        from vic_drake.realdata import read_phantom_map

        return cls.from_map_data(
            read_phantom_map(require_data_dir(data_dir) / "phantom_map"), lookup=lookup
        )

    @property
    def bounds(self):
        return (self.x_m[0], self.x_m[-1], self.y_m[0], self.y_m[-1])

    def sample(self, x, y) -> TissueSample:
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        if self.lookup == "nearest":
            ix = np.clip(
                np.rint(np.interp(x, self.x_m, np.arange(self.x_m.size))),
                0,
                self.x_m.size - 1,
            ).astype(int)
            iy = np.clip(
                np.rint(np.interp(y, self.y_m, np.arange(self.y_m.size))),
                0,
                self.y_m.size - 1,
            ).astype(int)
            gx = np.where(
                (x >= self.x_m[0]) & (x <= self.x_m[-1]), self.dz_dx_grid[ix, iy], 0.0
            )
            gy = np.where(
                (y >= self.y_m[0]) & (y <= self.y_m[-1]), self.dz_dy_grid[ix, iy], 0.0
            )
            return TissueSample(
                self.surface_m[ix, iy],
                gx,
                gy,
                self.kappa_grid[ix, iy],
                self.lam_grid[ix, iy],
            )
        i0, i1, wx, in_x = _axis_weights(self.x_m, x)
        j0, j1, wy, in_y = _axis_weights(self.y_m, y)

        def interp(g):
            return (
                (1 - wx) * (1 - wy) * g[i0, j0]
                + wx * (1 - wy) * g[i1, j0]
                + (1 - wx) * wy * g[i0, j1]
                + wx * wy * g[i1, j1]
            )

        return TissueSample(
            surface_z_m=interp(self.surface_m),
            dz_dx=np.where(in_x, interp(self.dz_dx_grid), 0.0),
            dz_dy=np.where(in_y, interp(self.dz_dy_grid), 0.0),
            kappa=interp(self.kappa_grid),
            lam=interp(self.lam_grid),
        )
