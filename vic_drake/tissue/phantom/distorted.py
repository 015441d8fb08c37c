"""A phantom as a wrong map sees it: scaled kappa and lambda, offset and shift.

The controller reads its own map of the tissue; :func:`with_map_errors` gives
that map with the errors of a real estimate: kappa and lambda scaled, the
surface raised (``surface_offset_m`` > 0: the map puts the surface higher
than it is) and the whole map shifted in x and y (a registration error: the
map's feature at (x, y) appears at (x + shift_x, y + shift_y)).
"""

from __future__ import annotations

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom.base import Phantom, TissueSample
from vic_drake.tissue.phantom.grid import GridPhantom


class DistortedPhantom(Phantom):
    """Another phantom seen through map errors (see the module docstring)."""

    def __init__(
        self,
        base: Phantom,
        *,
        kappa_scale: float,
        lam_scale: float,
        surface_offset_m: float,
        shift_x_m: float,
        shift_y_m: float,
    ):
        self._base = base
        self._errors = (
            float(kappa_scale),
            float(lam_scale),
            float(surface_offset_m),
            float(shift_x_m),
            float(shift_y_m),
        )
        self.beta = base.beta
        self.name = f"{getattr(base, 'name', 'phantom')} (map errors)"

    @property
    def bounds(self):
        x0, x1, y0, y1 = self._base.bounds
        _, _, _, sx, sy = self._errors
        return (x0 + sx, x1 + sx, y0 + sy, y1 + sy)

    def sample(self, x, y) -> TissueSample:
        ks, ls, dz, sx, sy = self._errors
        s = self._base.sample(np.asarray(x, float) - sx, np.asarray(y, float) - sy)
        return TissueSample(
            s.surface_z_m + dz, s.dz_dx, s.dz_dy, ks * s.kappa, ls * s.lam
        )


def with_map_errors(
    phantom: Phantom,
    *,
    kappa_scale: float = 1.0,
    lam_scale: float = 1.0,
    surface_offset_m: float = 0.0,
    shift_x_m: float = 0.0,
    shift_y_m: float = 0.0,
) -> Phantom:
    """The phantom as a map with these errors; the phantom itself when none.

    A :class:`GridPhantom` stays a grid (same lookup, axes shifted, grids
    scaled), so the controller's lookup is kept; any other
    phantom is wrapped in a :class:`DistortedPhantom`.
    """
    errors = (kappa_scale, lam_scale, surface_offset_m, shift_x_m, shift_y_m)
    if errors == (1.0, 1.0, 0.0, 0.0, 0.0):
        return phantom
    if isinstance(phantom, GridPhantom):
        return GridPhantom(
            x_m=phantom.x_m + shift_x_m,
            y_m=phantom.y_m + shift_y_m,
            z_m=phantom.surface_m - phantom.surface_offset_m,
            kappa=phantom.kappa_grid * kappa_scale,
            lam=phantom.lam_grid * lam_scale,
            beta=phantom.beta,
            surface_offset_m=phantom.surface_offset_m + surface_offset_m,
            lookup=phantom.lookup,
            name=f"{phantom.name} (map errors)",
        )
    return DistortedPhantom(
        phantom,
        kappa_scale=kappa_scale,
        lam_scale=lam_scale,
        surface_offset_m=surface_offset_m,
        shift_x_m=shift_x_m,
        shift_y_m=shift_y_m,
    )


def with_surface_profile(phantom: Phantom, x_m, offsets_m) -> GridPhantom:
    """A grid phantom whose surface is raised by a profile along x.

    The offset is piecewise linear through the points (``x_m[i]``,
    ``offsets_m[i]``) and held at the end values beyond them (a tissue
    raised under a scan track by what its two ends measured); kappa, lambda
    and the lookup are the phantom's, the slopes follow the raised surface.

    Raises:
        VicDrakeError: not a :class:`GridPhantom`, or the points are not
            finite, of one length >= 2, and strictly increasing in x.
    """
    if not isinstance(phantom, GridPhantom):
        raise VicDrakeError(
            f"a surface profile needs a grid phantom; got {type(phantom).__name__}"
        )
    xs, offs = np.asarray(x_m, float), np.asarray(offsets_m, float)
    if (
        xs.ndim != 1
        or xs.shape != offs.shape
        or xs.size < 2
        or not np.all(np.isfinite(xs))
        or not np.all(np.isfinite(offs))
        or np.any(np.diff(xs) <= 0)
    ):
        raise VicDrakeError(
            "a surface profile needs finite points of one length >= 2, strictly "
            f"increasing in x; got x_m={x_m!r}, offsets_m={offsets_m!r}"
        )
    raise_x = np.interp(phantom.x_m, xs, offs)
    return _raised(phantom, raise_x[:, None], "surface profile")


def _raised(phantom: GridPhantom, raise_m, label: str) -> GridPhantom:
    """``phantom`` with its surface raised by ``raise_m`` (broadcast on its
    grid); kappa, lambda, beta and the lookup are kept."""
    return GridPhantom(
        x_m=phantom.x_m,
        y_m=phantom.y_m,
        z_m=phantom.surface_m - phantom.surface_offset_m + raise_m,
        kappa=phantom.kappa_grid,
        lam=phantom.lam_grid,
        beta=phantom.beta,
        surface_offset_m=phantom.surface_offset_m,
        lookup=phantom.lookup,
        name=f"{phantom.name} ({label})",
    )


def with_surface_plane(
    phantom: Phantom, offset_m: float, gradient, origin_m
) -> GridPhantom:
    """A grid phantom whose surface is raised by a plane: a placement.

    The raise at (x, y) is ``offset_m + gx (x - x0) + gy (y - y0)``,
    (gx, gy) = ``gradient`` (m/m), (x0, y0) = ``origin_m``, over the whole
    grid (a phantom put back on the rig higher and tilted: the plane goes on
    beyond the scan track); kappa, lambda and the lookup are the phantom's,
    the slopes follow the raised surface.

    Raises:
        VicDrakeError: not a :class:`GridPhantom`, or the numbers are not
            finite pairs.
    """
    if not isinstance(phantom, GridPhantom):
        raise VicDrakeError(
            f"a surface plane needs a grid phantom; got {type(phantom).__name__}"
        )
    g, o = np.asarray(gradient, float), np.asarray(origin_m, float)
    if (
        g.shape != (2,)
        or o.shape != (2,)
        or not np.all(np.isfinite(g))
        or not np.all(np.isfinite(o))
        or not np.isfinite(offset_m)
    ):
        raise VicDrakeError(
            "a surface plane needs a finite offset and finite (x, y) pairs for its "
            f"gradient and origin; got offset_m={offset_m!r}, gradient={gradient!r}, "
            f"origin_m={origin_m!r}"
        )
    raise_xy = (
        float(offset_m)
        + g[0] * (phantom.x_m[:, None] - o[0])
        + g[1] * (phantom.y_m[None, :] - o[1])
    )
    return _raised(phantom, raise_xy, "surface plane")


__all__ = [
    "DistortedPhantom",
    "with_map_errors",
    "with_surface_plane",
    "with_surface_profile",
]
