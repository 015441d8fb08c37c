"""A tissue map against the phantom it was palpated on: errors and ribs.

:func:`compare_with_phantom` gives the RMS errors of the kappa, lambda and
surface maps against the phantom's truth, and the rib positions
(:func:`vic_drake.analysis.ribs.find_ribs`: peaks of kappa along x, averaged over a band in y by
:func:`band_profile`) found on the map and on the truth.
"""

from dataclasses import dataclass

import numpy as np

from vic_drake.analysis.ribs import find_ribs
from vic_drake.estimation.tissue_map import TissueMap


def band_profile(x_m, y_m, field, y_line: float, half_width_m: float) -> np.ndarray:
    """Mean of field[ix, iy] over |y - y_line| <= half_width_m, per x."""
    band = np.abs(np.asarray(y_m) - y_line) <= half_width_m + 1e-12
    if not band.any():
        band = np.abs(np.asarray(y_m) - y_line) == np.min(
            np.abs(np.asarray(y_m) - y_line)
        )
    return np.asarray(field)[:, band].mean(axis=1)


@dataclass(frozen=True)
class MapComparison:
    """A map against its phantom's truth over the map grid.

    Attributes:
        kappa_rmse_pct, lambda_rmse_pct: RMS of (est - true) / true, %.
        surface_rmse_mm: RMS of est - true surface height, mm.
        ribs_true, ribs_found: rib x positions, m (see :func:`compare_with_phantom`).
        rib_errors_m: |found - true| of each true rib's nearest found rib.
        y_line_m, band_m: the scan line the ribs are read on.
    """

    kappa_rmse_pct: float
    lambda_rmse_pct: float
    surface_rmse_mm: float
    ribs_true: tuple[float, ...]
    ribs_found: tuple[float, ...]
    rib_errors_m: tuple[float, ...]
    y_line_m: float
    band_m: float


def compare_with_phantom(
    tmap: TissueMap,
    phantom,
    *,
    y_line_m: float | None = None,
    band_m: float = 0.01,
    edge_m: float = 0.01,
    chunk_size: int = 200_000,
) -> MapComparison:
    """Errors of a map against the phantom it was palpated on.

    Ribs are peaks of kappa along x, averaged over ``y_line_m +- band_m``
    (default: the map's middle y). Truth: for a phantom with
    ``rib_centres_x`` (the synthetic chest) its rib centre lines at
    ``y_line_m``; otherwise (the measured map) the peaks that
    :func:`find_ribs` finds on the phantom's own kappa on the same grid and
    band. Ribs within ``edge_m`` of the map's x edges are left out of both
    lists (a peak at the edge cannot be located). The truth is sampled in
    blocks of about ``chunk_size`` grid points.
    """
    xs, ys = tmap.x_m, tmap.y_m
    # Sums of squared errors, accumulated over blocks of x-rows so the truth
    # of a 2 M-point map is never held whole.
    sums = np.zeros(3)
    rows = max(1, chunk_size // ys.size)
    for i0 in range(0, xs.size, rows):
        i1 = min(xs.size, i0 + rows)
        X, Y = np.meshgrid(xs[i0:i1], ys, indexing="ij")
        truth = phantom.sample(X, Y)
        sums += (
            np.sum(((tmap.kappa[i0:i1] - truth.kappa) / truth.kappa) ** 2),
            np.sum(((tmap.lam[i0:i1] - truth.lam) / truth.lam) ** 2),
            np.sum((tmap.surface_z_m[i0:i1] - truth.surface_z_m) ** 2),
        )
    n = xs.size * ys.size
    kappa_pct = float(100.0 * np.sqrt(sums[0] / n))
    lam_pct = float(100.0 * np.sqrt(sums[1] / n))
    surface_mm = float(1e3 * np.sqrt(sums[2] / n))
    y_line = float(np.mean([ys[0], ys[-1]])) if y_line_m is None else float(y_line_m)
    lo, hi = xs[0] + edge_m, xs[-1] - edge_m

    def inside(values):
        return tuple(float(v) for v in np.sort(values) if lo <= v <= hi)

    found = inside(
        find_ribs(xs, band_profile(xs, ys, tmap.kappa, y_line, band_m)).position_m
    )
    if hasattr(phantom, "rib_centres_x"):
        true = inside(np.asarray(phantom.rib_centres_x(y_line)).ravel())
    else:
        band = np.abs(ys - y_line) <= band_m + 1e-12
        if not band.any():
            band = np.abs(ys - y_line) == np.min(np.abs(ys - y_line))
        X, Y = np.meshgrid(xs, ys[band], indexing="ij")
        true_kappa = phantom.sample(X, Y).kappa
        true = inside(find_ribs(xs, true_kappa.mean(axis=1)).position_m)
    errors = tuple(
        float(np.min(np.abs(np.asarray(found) - t))) if found else float("nan")
        for t in true
    )
    return MapComparison(
        kappa_rmse_pct=kappa_pct,
        lambda_rmse_pct=lam_pct,
        surface_rmse_mm=surface_mm,
        ribs_true=true,
        ribs_found=found,
        rib_errors_m=errors,
        y_line_m=y_line,
        band_m=band_m,
    )
