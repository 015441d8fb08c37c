"""The synthetic chest as a measured phantom's twin: its parameters fitted to a map.

:func:`fit_synthetic_chest` derives every shape and tissue parameter of
:class:`~vic_drake.tissue.phantom.synthetic_chest.SyntheticChestParams` from
a measured GP map (:class:`vic_drake.realdata.PhantomMapData`), by least
squares on the model the phantom evaluates:

1. Surface (the tissue surface, map z + the map's surface offset): the dome
   plus anisotropic Gaussian hump of ``SyntheticChestPhantom._surface``,
   fitted over the whole map with the samples within ``band_m`` of the scan
   line weighted ``line_weight`` times (the scans run there), from two
   starts (the better fit is kept).
2. kappa along the scan line (the mean over the band): a Gaussian soft-tissue
   plateau plus one Gaussian band per rib with a shared width. Ribs are the
   peaks of that profile with a prominence of at least ``rib_prominence``
   times its median (the rule claim C3 applies to the map). The rib with
   the smallest rise is the muscle-covered one; the rise of a bare rib
   (kappa_rib - kappa_soft) is the median rise of the others, each rib's
   scale its own rise over it, and muscle_factor the covered rib's.
3. Rib lines: per rib and map column y, the position of the kappa maximum
   within ``rib_track_m`` of the rib; a shared tilt and bend (per-rib
   intercepts) by linear least squares.
4. Texture: the RMS of the relative kappa residual along the scan line.
5. lambda = lam_ref (kappa / kappa_ref)^p by least squares in log-log over
   the whole map, kappa_ref = the map's median kappa.

The phantom's defaults are this fit on the paper's map, rounded; the
command is in docs/decisions.md ("Synthetic chest: the measured phantom's
twin").
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import find_peaks

from vic_drake.errors import VicDrakeError
from vic_drake.realdata import PhantomMapData
from vic_drake.tissue.phantom.synthetic_chest import SyntheticChestParams


@dataclass(frozen=True)
class ChestFit:
    """The fitted chest and how well it matches the map.

    Attributes:
        params: the fitted SyntheticChestParams (torso placement, beta and
            texture seed from the ``base`` given to the fit).
        diagnostics: residuals and raw fitted values (JSON-ready): surface
            RMS over the map and along the scan line (m), kappa RMS along
            the line (N/m^beta), lambda's log residual SD, the rib positions
            (m) and rises (N/m^beta).
    """

    params: SyntheticChestParams
    diagnostics: dict


def _surface_model(p, X, Y):
    top, x0, y0, cx, cy, a, xs, ys, rx, ry = p
    r2 = ((X - xs) / rx) ** 2 + ((Y - ys) / ry) ** 2
    return top - cx * (X - x0) ** 2 - cy * (Y - y0) ** 2 + a * np.exp(-r2)


def _surface_jacobian(p, X, Y):
    """d(_surface_model)/dp, (n_samples, 10)."""
    _, x0, y0, cx, cy, a, xs, ys, rx, ry = p
    dx, dy = X - xs, Y - ys
    e = np.exp(-((dx / rx) ** 2) - (dy / ry) ** 2)
    cols = (
        np.ones_like(X),
        2 * cx * (X - x0),
        2 * cy * (Y - y0),
        -((X - x0) ** 2),
        -((Y - y0) ** 2),
        e,
        a * e * 2 * dx / rx**2,
        a * e * 2 * dy / ry**2,
        a * e * 2 * dx**2 / rx**3,
        a * e * 2 * dy**2 / ry**3,
    )
    return np.stack([c.ravel() for c in cols], axis=1)


def _fit_surface(x, y, Z, line, line_weight):
    X, Y = np.meshgrid(x, y, indexing="ij")
    w = np.where(line[None, :], line_weight, 1.0) * np.ones_like(Z)
    i_top = np.unravel_index(np.argmax(Z), Z.shape)
    x_top, y_top = x[i_top[0]], y[i_top[1]]
    span_x, span_y = np.ptp(x), np.ptp(y)
    starts = (
        # A dome centred on the highest point with a small hump there.
        [Z.max(), x_top, y_top, 0.5, 3.0, 0.01, x_top, y_top, span_x / 5, span_y / 2],
        # A broad dome at the map's centre and a hump at the highest point.
        [Z.max(), x.mean(), y.mean(), 1.0, 1.0, 0.02, x_top, y_top, span_x / 3, span_y],
    )
    best = None
    for p0 in starts:
        fit = least_squares(
            lambda p: ((_surface_model(p, X, Y) - Z) * w).ravel(),
            p0,
            jac=lambda p: _surface_jacobian(p, X, Y) * w.ravel()[:, None],
            x_scale="jac",
            method="lm",  # MINPACK's QR: no SVD of the 20k x 10 Jacobian per step.
        )
        if fit.success and (best is None or fit.cost < best.cost):
            best = fit
    if best is None:
        raise VicDrakeError("fit_synthetic_chest: the surface fit did not converge")
    res = _surface_model(best.x, X, Y) - Z
    return (
        best.x,
        float(np.sqrt(np.mean(res**2))),
        float(np.sqrt(np.mean(res[:, line] ** 2))),
    )


def _kappa_model(p, x, n):
    k_mid, x_mid, width, sigma = p[:4]
    centres, rises = p[4 : 4 + n], p[4 + n : 4 + 2 * n]
    out = k_mid * np.exp(-0.5 * ((x - x_mid) / width) ** 2)
    for c, a in zip(centres, rises, strict=True):
        out = out + a * np.exp(-0.5 * ((x - c) / sigma) ** 2)
    return out


def _fit_kappa_line(x, profile, prominence):
    peaks, props = find_peaks(profile, prominence=prominence * np.median(profile))
    n = len(peaks)
    if n < 2:
        raise VicDrakeError(
            f"fit_synthetic_chest: found {n} rib(s) in the kappa profile along the scan "
            f"line (peaks with prominence >= {prominence:g} x median); needs at least 2"
        )
    p0 = [np.median(profile), x.mean(), np.ptp(x), 0.007, *x[peaks]]
    p0 += list(props["prominences"])
    lo = [0.0, x.min() - np.ptp(x), 0.01, 0.002, *(x[peaks] - 0.01), *([0.0] * n)]
    hi = [np.inf, x.max() + np.ptp(x), np.inf, 0.03, *(x[peaks] + 0.01)]
    hi += [np.inf] * n
    fit = least_squares(
        lambda p: _kappa_model(p, x, n) - profile, p0, bounds=(lo, hi), x_scale="jac"
    )
    model = _kappa_model(fit.x, x, n)
    return fit.x, n, model


def _fit_rib_lines(x, y, kappa, centres, scan_y, track_m):
    rows, target = [], []
    n = len(centres)
    for i, c in enumerate(centres):
        near = np.abs(x - c) <= track_m
        for j, yj in enumerate(y):
            dy = yj - scan_y
            row = np.zeros(n + 2)
            row[i], row[n], row[n + 1] = 1.0, dy, dy**2
            rows.append(row)
            target.append(x[near][np.argmax(kappa[near, j])])
    coef, *_ = np.linalg.lstsq(np.array(rows), np.array(target), rcond=None)
    return float(coef[n]), float(coef[n + 1])


def fit_synthetic_chest(
    map_data: PhantomMapData,
    *,
    base: SyntheticChestParams | None = None,
    band_m: float = 0.01,
    line_weight: float = 5.0,
    rib_prominence: float = 0.05,
    rib_track_m: float = 0.012,
) -> ChestFit:
    """Fits the synthetic chest to a measured map (module doc: the method).

    Args:
        map_data: the measured map (``read_phantom_map``).
        base: torso placement (centre, extent, height), beta and texture
            seed/modes to keep; its ``center_y_m`` is the scan line
            (default: SyntheticChestParams()).
        band_m: half-width of the band around the scan line, m (> 0).
        line_weight: weight of the band's samples in the surface fit (>= 1).
        rib_prominence: a rib's minimum prominence over the median kappa.
        rib_track_m: half-width of the search for a rib's line across y, m.

    Returns:
        ChestFit.

    Raises:
        VicDrakeError: bad options, a scan line outside the map, fewer than 2
            ribs, or a fit that does not converge.
    """
    base = SyntheticChestParams() if base is None else base
    for name, value, low in (
        ("band_m", band_m, 0.0),
        ("rib_prominence", rib_prominence, 0.0),
        ("rib_track_m", rib_track_m, 0.0),
    ):
        if not (np.isfinite(value) and value > low):
            raise VicDrakeError(
                f"fit_synthetic_chest: {name} must be > 0; got {value!r}"
            )
    if not (np.isfinite(line_weight) and line_weight >= 1.0):
        raise VicDrakeError(
            f"fit_synthetic_chest: line_weight must be >= 1; got {line_weight!r}"
        )
    x, y = map_data.x_m, map_data.y_m
    scan_y = base.center_y_m
    line = np.abs(y - scan_y) <= band_m
    if not line.any():
        raise VicDrakeError(
            f"fit_synthetic_chest: the scan line y = {scan_y} (base.center_y_m) is not "
            f"within {band_m} m of the map's y range [{y.min()}, {y.max()}]"
        )
    profile = map_data.kappa[:, line].mean(axis=1)
    k, n, model = _fit_kappa_line(x, profile, rib_prominence)  # Fails early.
    Z = map_data.z_m + map_data.surface_offset_m
    s, rms_all, rms_line = _fit_surface(x, y, Z, line, line_weight)
    centres, rises = k[4 : 4 + n], k[4 + n : 4 + 2 * n]
    muscle = int(np.argmin(rises))
    rise = float(np.median(np.delete(rises, muscle)))
    scales = rises / rise
    tilt, bend = _fit_rib_lines(x, y, map_data.kappa, centres, scan_y, rib_track_m)
    texture = float(np.sqrt(np.mean(((profile - model) / model) ** 2)))
    kappa, lam = map_data.kappa.ravel(), map_data.lam.ravel()
    kappa_ref = float(np.median(kappa))
    slope, intercept = np.polyfit(np.log(kappa / kappa_ref), np.log(lam), 1)
    lam_resid = np.log(lam) - (intercept + slope * np.log(kappa / kappa_ref))
    cx, cy = base.center_x_m, base.center_y_m
    params = dataclasses.replace(
        base,
        top_z_m=float(s[0]),
        dome_dx_m=float(s[1] - cx),
        dome_dy_m=float(s[2] - cy),
        curvature_x_per_m=float(s[3]),
        curvature_y_per_m=float(s[4]),
        shoulder_rise_m=float(s[5]),
        shoulder_dx_m=float(s[6] - cx),
        shoulder_dy_m=float(s[7] - cy),
        shoulder_radius_m=float(abs(s[8])),
        shoulder_radius_y_m=float(abs(s[9])),
        rib_offsets_x_m=tuple(float(c - cx) for c in centres),
        rib_scales=tuple(
            1.0 if i == muscle else float(v) for i, v in enumerate(scales)
        ),
        rib_tilt=tilt,
        rib_bend_per_m=bend,
        rib_sigma_m=float(k[3]),
        muscle_rib_index=muscle,
        muscle_factor=float(scales[muscle]),
        kappa_soft=float(k[0]),
        kappa_rib=float(k[0] + rise),
        soft_center_dx_m=float(k[1] - cx),
        soft_width_x_m=float(k[2]),
        kappa_texture=texture,
        lam_ref=float(np.exp(intercept)),
        kappa_ref=kappa_ref,
        lam_exponent=float(slope),
    )
    diagnostics = {
        "surface_rms_m": rms_all,
        "surface_rms_scan_line_m": rms_line,
        "kappa_rms_scan_line": float(np.sqrt(np.mean((profile - model) ** 2))),
        "lambda_log_residual_sd": float(np.std(lam_resid)),
        "rib_x_m": [float(c) for c in centres],
        "rib_rise": [float(a) for a in rises],
        "scan_y_m": float(scan_y),
    }
    return ChestFit(params=params, diagnostics=diagnostics)


__all__ = ["ChestFit", "fit_synthetic_chest"]
