"""Where a resting phantom was placed against the map: a plane fitted in contact.

A phantom put back on the rig sits a few mm higher or lower than the map says
and may be tilted. :func:`fit_surface_placement` reads that placement from a
scan log as a rigid registration with two parameters: the surface against the
map is ``c + a s``, with ``s`` the distance along the track from its middle
(the principal direction of the tip's path). Across the track a scan says
nothing (the shared tracks stray 5-8 mm in y, in step with x), so the plane
has no tilt there.

The evidence is the apparent surface under the tip in contact
(:func:`apparent_surface_m`): the tip height plus the penetration that makes
the tissue law give the measured force at the map's kappa, lambda, beta,
with the relaxed part of the elastic term (the states built up along the
log's own penetration history) as the simulated tissue has it. It reads the
force that compare-real then scores, so a placement from it fits the mean
force level and its linear trend along the track by construction; what it
does not fit is everything else (docs/decisions.md, "Phantom placement from
the in-contact surface").

The fit runs on the samples of the scan window
(:func:`~vic_drake.analysis.contact.scan_window`, from 1 s after the first
contact: the impact transient is out), binned every :data:`BIN_M` along the
track (each cm counts once, however long the tip dwelt there), by a Huber
line through the bins' medians. Its 1-sigma comes from the bins' scatter
about the line; the bins are not independent (the map's own error is
correlated over cm), so it is a lower bound.
"""

from typing import NamedTuple

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import require_columns
from vic_drake.analysis.contact import pressing_force_N, scan_window
from vic_drake.analysis.phantom_motion import penetration_m
from vic_drake.errors import VicDrakeError
from vic_drake.tissue.relaxation import DEFAULT_RELAXATION, relaxation_history

#: Bin length along the track, m.
BIN_M = 0.01
#: Fewest contact samples a bin needs (50 ms at 500 Hz).
MIN_BIN_SAMPLES = 25
#: Fewest bins, and the shortest span of their centres, m, for a slope.
MIN_BINS = 4
MIN_SPAN_M = 0.02
#: Huber's tuning constant, in robust scales (95 % efficiency for Gaussian
#: residuals).
HUBER_K = 1.345
#: Passes of the self-consistent relaxation history.
RELAXATION_PASSES = 2


class SurfacePlacement(NamedTuple):
    """The plane a resting phantom's surface lay on, against the map.

    Attributes:
        offset_m: surface - map at the origin, m (> 0: the map is low).
        slope_m_per_m: the surface's rise per m along ``direction``.
        offset_sigma_m, slope_sigma_m: their 1-sigma (see the module doc).
        x0_m, y0_m: the origin (the mean of the track's bin centres), m.
        direction: unit vector (dx, dy) along the track, dx >= 0.
        span_m: distance between the first and the last bin centre, m.
        start_m: the first bin centre's distance from the origin along
            ``direction``, m (<= 0; the last is at start_m + span_m; the
            origin is the middle of the span only when the bins are even).
        bins: bins in the fit. samples: contact samples in them.
        residual_rms_m: RMS of the bins' medians about the plane, m.
    """

    offset_m: float
    slope_m_per_m: float
    offset_sigma_m: float
    slope_sigma_m: float
    x0_m: float
    y0_m: float
    direction: tuple[float, float]
    span_m: float
    start_m: float
    bins: int
    samples: int
    residual_rms_m: float

    @property
    def gradient(self) -> tuple[float, float]:
        """The plane's rise per m along x and y."""
        return (
            self.slope_m_per_m * self.direction[0],
            self.slope_m_per_m * self.direction[1],
        )

    def offset_at(self, x_m, y_m) -> np.ndarray:
        """The plane's offset at (x, y), m."""
        gx, gy = self.gradient
        return (
            self.offset_m
            + gx * (np.asarray(x_m, float) - self.x0_m)
            + gy * (np.asarray(y_m, float) - self.y0_m)
        )

    def as_dict(self) -> dict:
        return {**self._asdict(), "direction": list(self.direction)}


def apparent_surface_m(
    df: pd.DataFrame, phantom, *, relaxation=DEFAULT_RELAXATION
) -> np.ndarray:
    """The tissue surface under the tip that the force says, minus the map's, m.

    In contact: ``z + eps - map``, with ``eps`` solving
    ``F = kappa (u - g . S) + lam u eps_dot``, ``u = eps^beta``: the viscous
    inversion of :func:`~vic_drake.analysis.phantom_motion.penetration_m`
    gives ``kappa + lam eps_dot``; the relaxation states ``S`` follow the
    penetration history from the log's start (relaxed there), found by
    :data:`RELAXATION_PASSES` passes. NaN out of contact.

    Args:
        df: canonical scan frame (t_s, x_m, y_m, z_m, force_sensor_z_N).
        phantom: the map (surface_z, kappa, lam, beta).
        relaxation: the tissue's relaxation, None for plain Hunt-Crossley.
    """
    require_columns(df, "t_s", "x_m", "y_m", "z_m", "force_sensor_z_N")
    x, y = df["x_m"].to_numpy(float), df["y_m"].to_numpy(float)
    eps = penetration_m(df, phantom)
    ok = np.isfinite(eps)
    beta = phantom.beta
    if relaxation is not None and relaxation.n_branches and ok.any():
        t = df["t_s"].to_numpy(float)
        f = np.maximum(pressing_force_N(df), 0.0)
        kappa = np.asarray(phantom.kappa(x, y), float)
        u0 = np.where(ok, eps, 0.0) ** beta
        with np.errstate(invalid="ignore", divide="ignore"):
            stiff = np.where(ok, f / u0, np.nan)  # kappa + lam eps_dot
        g = np.asarray(relaxation.fractions, float)
        u = u0
        for _ in range(RELAXATION_PASSES):
            states = relaxation_history(t, u, relaxation.time_constants_s)
            u = np.where(ok, u0 + kappa * (states @ g) / stiff, 0.0)
        eps = np.where(ok, u ** (1.0 / beta), np.nan)
    z = df["z_m"].to_numpy(float)
    return z + eps - np.asarray(phantom.surface_z(x, y), float)


def _huber_line(s, v):
    """Huber fit of v = c + a s; (c, a), covariance, weights, robust scale."""
    design = np.c_[np.ones(s.size), s]
    w = np.ones(s.size)
    coef = np.linalg.lstsq(design, v, rcond=None)[0]
    scale = 0.0
    for _ in range(50):
        r = v - design @ coef
        scale = 1.4826 * float(np.median(np.abs(r - np.median(r))))
        if scale <= 0:
            break
        k = HUBER_K * scale
        w = np.minimum(1.0, k / np.maximum(np.abs(r), 1e-300))
        sw = np.sqrt(w)
        new = np.linalg.lstsq(design * sw[:, None], v * sw, rcond=None)[0]
        done = np.allclose(new, coef, rtol=0, atol=1e-9)
        coef = new
        if done:
            break
    r = v - design @ coef
    dof = max(float(np.sum(w)) - 2.0, 1.0)
    var = float(np.sum(w * r**2)) / dof
    cov = var * np.linalg.inv(design.T @ (design * w[:, None]))
    return coef, cov, r


def fit_surface_placement(
    df: pd.DataFrame,
    phantom,
    *,
    relaxation=DEFAULT_RELAXATION,
    window: np.ndarray | None = None,
) -> SurfacePlacement | None:
    """The plane of a resting phantom's surface against the map; None when the
    log cannot give one (see the module doc).

    Args:
        df: canonical scan frame (t_s, x_m, y_m, z_m, z_d_m, force_sensor_z_N).
        phantom: the map the surface is read against (the published one).
        relaxation: the tissue's relaxation (:func:`apparent_surface_m`).
        window: boolean mask of the samples to use; default the scan window.

    Returns:
        :class:`SurfacePlacement`, or None with fewer than :data:`MIN_BINS`
        bins of :data:`MIN_BIN_SAMPLES` contact samples or a span under
        :data:`MIN_SPAN_M`.

    Raises:
        VicDrakeError: ``window`` of the wrong length.
    """
    if window is None:
        window = scan_window(df)
    window = np.asarray(window, bool)
    if window.shape != (len(df),):
        raise VicDrakeError(
            f"window must be a boolean mask of {len(df)} samples; got shape "
            f"{window.shape}"
        )
    surface = apparent_surface_m(df, phantom, relaxation=relaxation)
    # (A finite surface is in contact: penetration_m is NaN at or below the threshold.)
    use = window & np.isfinite(surface)
    if use.sum() < MIN_BINS * MIN_BIN_SAMPLES:
        return None
    xy = np.c_[df["x_m"].to_numpy(float)[use], df["y_m"].to_numpy(float)[use]]
    v = surface[use]
    centre = xy.mean(axis=0)
    # The track's direction: the principal axis of the tip's path.
    _, _, vt = np.linalg.svd(xy - centre, full_matrices=False)
    d = vt[0] if vt[0][0] >= 0 else -vt[0]
    along = (xy - centre) @ d
    edges = np.arange(along.min(), along.max() + BIN_M, BIN_M)
    k = np.clip(np.digitize(along, edges) - 1, 0, max(edges.size - 2, 0))
    mids, meds, count = [], [], 0
    for b in np.unique(k):
        sel = k == b
        if sel.sum() >= MIN_BIN_SAMPLES:
            mids.append(float(np.mean(along[sel])))
            meds.append(float(np.median(v[sel])))
            count += int(sel.sum())
    mids, meds = np.array(mids), np.array(meds)
    if mids.size < MIN_BINS or mids.max() - mids.min() < MIN_SPAN_M:
        return None
    # The origin: the middle of the bins, so offset and slope are uncorrelated
    # when the bins are evenly weighted.
    mid = float(np.mean(mids))
    coef, cov, r = _huber_line(mids - mid, meds)
    x0, y0 = centre + mid * d
    return SurfacePlacement(
        offset_m=float(coef[0]),
        slope_m_per_m=float(coef[1]),
        offset_sigma_m=float(np.sqrt(cov[0, 0])),
        slope_sigma_m=float(np.sqrt(cov[1, 1])),
        x0_m=float(x0),
        y0_m=float(y0),
        direction=(float(d[0]), float(d[1])),
        span_m=float(mids.max() - mids.min()),
        start_m=float(mids.min() - mid),
        bins=int(mids.size),
        samples=count,
        residual_rms_m=float(np.sqrt(np.mean(r**2))),
    )


__all__ = [
    "BIN_M",
    "HUBER_K",
    "MIN_BINS",
    "MIN_BIN_SAMPLES",
    "MIN_SPAN_M",
    "RELAXATION_PASSES",
    "SurfacePlacement",
    "apparent_surface_m",
    "fit_surface_placement",
]
