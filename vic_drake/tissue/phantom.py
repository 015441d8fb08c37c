"""Phantoms: where the tissue surface is and how stiff and viscous it is.

A :class:`Phantom` answers, for points (x, y) in the robot base frame, the
tissue surface height z(x, y), its gradient, and the Hunt-Crossley
parameters kappa(x, y), lambda(x, y) for one exponent beta. Two kinds:

- :class:`GridPhantom`: a map on a regular grid, e.g. the paper's measured
  GP map (``phantom_map/``). Bilinear lookup (or nearest, as the real
  controller did). Outside the grid a query is clamped to the nearest grid
  edge: values extend constantly and the gradient across the edge is zero.
- :class:`SyntheticChestPhantom`: an analytic chest (torso, curvature,
  shoulder rise, ribs as stiff bands, one rib under muscle), the embedded
  default when the measured data is absent. Every parameter lives in
  :class:`SyntheticChestParams`. Outside its footprint it clamps likewise.

All methods are vectorised: x and y broadcast against each other.
"""

from __future__ import annotations

import bisect
import os
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError


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
    beta: float = 1.35

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
        cache = self.__dict__.get("_point_lookups")
        if cache is None or cache["owner"] != id(self):
            # First call, or a (shallow) copy of another phantom: own cache.
            cache = self.__dict__["_point_lookups"] = {"owner": id(self)}
        if isinstance(self, GridPhantom):
            key = ("grid", self.lookup)
        else:
            key = ("raster", float(resolution_m))
        if key not in cache:
            cache[key] = PointLookup(self, resolution_m=resolution_m)
        return cache[key]

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
        lookup: "bilinear" (default) or "nearest" (what the real controller did).
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
        beta: float = 1.35,
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


class PointLookup:
    """Fast scalar lookup of a phantom at one point (the per-tick query).

    ``Phantom.sample`` is vectorised numpy and costs 50-100 us for a single
    point, a large share of a 2 ms control tick. This answers the same query
    in a few microseconds with plain Python floats:

    - a :class:`GridPhantom` is used as is (its grids, gradient grids and
      lookup mode), so the result equals its ``sample`` to rounding;
    - any other phantom is rasterized once at ``resolution_m`` over its
      bounds (surface, gradient, kappa, lambda at the nodes, bilinear in
      between; 0.5 mm keeps the synthetic chest's surface within
      micrometres and kappa within 0.5 %).

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


@dataclass(frozen=True)
class SyntheticChestParams:
    """Every parameter of the synthetic chest phantom (base frame, SI units).

    The torso is a 33 x 33 x 23 cm block whose top is a smooth dome, placed
    where the real phantom lay on the rig (the measured map's region sits
    inside it), so the same scan scenarios run on both. Ribs run along y and
    are crossed by scans along x, as on the real phantom.
    """

    center_x_m: float = -0.06  # Torso centre, x.
    center_y_m: float = -0.36  # Torso centre, y.
    length_x_m: float = 0.33  # Torso extent along x (head-feet).
    width_y_m: float = 0.33  # Torso extent along y (left-right).
    height_m: float = 0.23  # Torso thickness; its base is at top_z_m - height_m.
    top_z_m: float = 0.112  # Highest surface point, m.
    curvature_x_per_m: float = 0.5  # Dome: z drops curvature * dx^2 along x.
    curvature_y_per_m: float = 1.0  # Dome: z drops curvature * dy^2 along y.
    shoulder_rise_m: float = 0.025  # Height of the shoulder rise in one corner.
    shoulder_dx_m: float = 0.15  # Shoulder centre relative to the torso centre, x.
    shoulder_dy_m: float = -0.15  # Shoulder centre relative to the torso centre, y.
    shoulder_radius_m: float = 0.07  # Gaussian radius of the shoulder rise.
    # Rib centre lines: x = center_x + offset + bend * (y - center_y)^2.
    rib_offsets_x_m: tuple[float, ...] = (-0.10, -0.055, -0.01, 0.035, 0.08)
    rib_bend_per_m: float = 0.6
    rib_sigma_m: float = 0.006  # Gaussian half-width of a rib's stiffness band.
    muscle_rib_index: int = 4  # The rib under the pectoral muscle (-1 for none).
    muscle_factor: float = 0.45  # Fraction of the rib's stiffness rise it keeps.
    kappa_soft: float = 2700.0  # Soft-tissue kappa, N/m^beta (measured 2,000-5,500).
    kappa_rib: float = 9800.0  # Peak kappa over a bare rib (measured up to 10,236).
    kappa_texture: float = 0.18  # Relative amplitude of smooth soft-tissue variation.
    # lambda = lam_ref * (kappa / kappa_ref)^lam_exponent: the measured map has
    # lambda rising faster than kappa (lambda/kappa 8 on soft tissue, 21 on ribs).
    lam_ref: float = 21000.0
    kappa_ref: float = 2545.0
    lam_exponent: float = 1.7
    beta: float = 1.35  # Hunt-Crossley exponent.
    texture_seed: int = 7  # Seed of the soft-tissue texture (deterministic).
    texture_modes: int = 6  # Number of sinusoidal texture modes.

    def __post_init__(self):
        for name in (
            "length_x_m",
            "width_y_m",
            "height_m",
            "rib_sigma_m",
            "shoulder_radius_m",
            "kappa_soft",
            "kappa_rib",
            "lam_ref",
            "kappa_ref",
            "beta",
        ):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise VicDrakeError(
                    f"SyntheticChestParams.{name} must be > 0, got {value!r}"
                )
        if self.kappa_rib < self.kappa_soft:
            raise VicDrakeError(
                f"SyntheticChestParams.kappa_rib ({self.kappa_rib}) must be >= "
                f"kappa_soft ({self.kappa_soft})"
            )
        if not 0 <= self.muscle_factor <= 1:
            raise VicDrakeError(
                f"SyntheticChestParams.muscle_factor must be in [0, 1], got {self.muscle_factor!r}"
            )
        if not -1 <= self.muscle_rib_index < len(self.rib_offsets_x_m):
            raise VicDrakeError(
                f"SyntheticChestParams.muscle_rib_index must be -1 or in "
                f"[0, {len(self.rib_offsets_x_m) - 1}], got {self.muscle_rib_index!r}"
            )
        if not 0 <= self.kappa_texture < 1:
            raise VicDrakeError(
                f"SyntheticChestParams.kappa_texture must be in [0, 1), got {self.kappa_texture!r}"
            )


class SyntheticChestPhantom(Phantom):
    """An analytic chest phantom: dome, shoulder, ribs under soft tissue."""

    def __init__(self, params: SyntheticChestParams | None = None):
        self.params = params or SyntheticChestParams()
        self.beta = self.params.beta
        self.name = "synthetic"
        rng = np.random.default_rng(self.params.texture_seed)
        n = self.params.texture_modes
        # Wavelengths of 4-12 cm, random phases and directions.
        self._tex_k = rng.uniform(2 * np.pi / 0.12, 2 * np.pi / 0.04, n)
        self._tex_dir = rng.uniform(0, np.pi, n)
        self._tex_phase = rng.uniform(0, 2 * np.pi, n)

    @property
    def bounds(self):
        p = self.params
        return (
            p.center_x_m - p.length_x_m / 2,
            p.center_x_m + p.length_x_m / 2,
            p.center_y_m - p.width_y_m / 2,
            p.center_y_m + p.width_y_m / 2,
        )

    @property
    def base_z_m(self) -> float:
        return self.params.top_z_m - self.params.height_m

    def rib_centres_x(self, y) -> np.ndarray:
        """x of every rib's centre line at y: array (n_ribs, *y.shape)."""
        p = self.params
        y = np.asarray(y, float)
        dy = y - p.center_y_m
        return np.array(
            [p.center_x_m + o + p.rib_bend_per_m * dy**2 for o in p.rib_offsets_x_m]
        )

    def _clamp(self, x, y):
        x_min, x_max, y_min, y_max = self.bounds
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        return np.clip(x, x_min, x_max), np.clip(y, y_min, y_max)

    def _surface(self, x, y):
        p = self.params
        dx, dy = x - p.center_x_m, y - p.center_y_m
        z = p.top_z_m - p.curvature_x_per_m * dx**2 - p.curvature_y_per_m * dy**2
        r2 = (dx - p.shoulder_dx_m) ** 2 + (dy - p.shoulder_dy_m) ** 2
        return z + p.shoulder_rise_m * np.exp(-r2 / p.shoulder_radius_m**2)

    def _kappa(self, x, y):
        p = self.params
        dx, dy = x - p.center_x_m, y - p.center_y_m
        tex = np.zeros_like(x)
        for k, a, ph in zip(self._tex_k, self._tex_dir, self._tex_phase):
            tex = tex + np.sin(k * (np.cos(a) * dx + np.sin(a) * dy) + ph)
        tex = tex / np.sqrt(len(self._tex_k) / 2.0)  # about unit RMS
        soft = p.kappa_soft * (1.0 + p.kappa_texture * np.tanh(tex))
        rib = np.zeros_like(x)
        for i, xc in enumerate(self.rib_centres_x(y)):
            scale = p.muscle_factor if i == p.muscle_rib_index else 1.0
            rib = np.maximum(
                rib, scale * np.exp(-0.5 * ((x - xc) / p.rib_sigma_m) ** 2)
            )
        return soft + (p.kappa_rib - soft) * rib

    def sample(self, x, y) -> TissueSample:
        xq, yq = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        xc, yc = self._clamp(xq, yq)
        h = 1e-5
        gx = (self._surface(xc + h, yc) - self._surface(xc - h, yc)) / (2 * h)
        gy = (self._surface(xc, yc + h) - self._surface(xc, yc - h)) / (2 * h)
        x_min, x_max, y_min, y_max = self.bounds
        gx = np.where((xq >= x_min) & (xq <= x_max), gx, 0.0)
        gy = np.where((yq >= y_min) & (yq <= y_max), gy, 0.0)
        kappa = self._kappa(xc, yc)
        p = self.params
        lam = p.lam_ref * (kappa / p.kappa_ref) ** p.lam_exponent
        return TissueSample(self._surface(xc, yc), gx, gy, kappa, lam)


PHANTOM_KINDS = ("synthetic", "measured")


def load_phantom(
    kind: str = "synthetic",
    *,
    data_dir: str | os.PathLike | None = None,
    lookup: str = "bilinear",
) -> Phantom:
    """Returns the phantom of the given kind ("synthetic" or "measured")."""
    if kind == "synthetic":
        return SyntheticChestPhantom()
    if kind == "measured":
        return GridPhantom.from_data_dir(data_dir, lookup=lookup)
    raise VicDrakeError(f"phantom kind must be one of {PHANTOM_KINDS}, got {kind!r}")


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
