"""Where a real phantom's surface lay at the end of a scan: the lift-off.

The counterpart of :func:`vic_drake.analysis.surface_offset.first_contact_offset`
at the other end of the track. After the scan window closes
(:func:`vic_drake.analysis.contact.scan_window` ends where the target jumps
up) the tip leaves the tissue at a few cm/s, and the force falls to the
sensor's bias. That fall is not the elastic curve read backwards: the
Hunt-Crossley viscous term ``lam u eps_dot`` (eps_dot < 0 while lifting)
and the relaxed part of the elastic term (``kappa g S``, the states built
up over the scan, :mod:`vic_drake.tissue.relaxation`) both lower the force,
so it reaches zero while the tip is still inside the tissue. Both terms are
known from the map and the tip's own motion, not from the force:

    F = kappa [u (1 + r eps_dot) - g . S],   u = (s - z)^beta,  r = lam / kappa,

so ``w = ((F / kappa + g . S) / (1 + r eps_dot))^(1/beta)`` is linear in the
tip height and meets zero at the surface ``s`` (kappa's scale drops out of
the line as in the first-contact fit, up to its small effect on the relaxed
term). The relaxation states need the penetration over the whole scan, so
the surface along the track: a constant offset or one per sample
(``history_offset_m``), by default the estimate itself (iterated).
"""

from typing import NamedTuple

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import require_columns
from vic_drake.analysis.contact import pressing_force_N
from vic_drake.analysis.surface_offset import (
    FREE_MARGIN_S,
    MIN_FREE_S,
    MIN_ONSET_SAMPLES,
    ONSET_HIGH_N,
    ONSET_LOW_N,
    ONSET_NOISE_Z,
)
from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTACT_THRESHOLD_N
from vic_drake.tissue.relaxation import (
    DEFAULT_RELAXATION,
    relaxation_history,
    relaxation_input,
)

#: The tip's velocity is the slope of its height over this many seconds on
#: either side of a sample (a least-squares line: the logged height's
#: 0.01 mm steps make a two-sample difference too noisy at 500 Hz).
VELOCITY_HALF_WINDOW_S = 0.01
#: Samples whose viscous factor ``1 + r eps_dot`` is below this are left out
#: of the fit: there the force hardly depends on the penetration.
MIN_VISCOUS_FACTOR = 0.2
#: Passes of the self-consistent relaxation history (history_offset_m None).
HISTORY_PASSES = 3


class LiftOff(NamedTuple):
    """The tissue's surface where the tip left it, against the map's.

    Attributes:
        offset_m: surface - map surface at (x_m, y_m), m (> 0: the map is low).
        sigma_m: 1-sigma of offset_m from the fit's residuals, m.
        surface_z_m: the surface height found, m.
        x_m, y_m: where the tip left (last sample of the fit), m.
        t_s: its time, s.
        samples: samples in the fit.
        bias_N: the pressing-force bias removed (free-space median after), N.
        speed_m_per_s: median lift speed over the fit, m/s.
        raw_offset_m: the same fit without the viscous and relaxation
            corrections (the plain elastic curve read backwards), m.
        kappa_scale: the fit's elastic modulus over the map's kappa
            (slope^beta): near 1 when the lift follows the model.
    """

    offset_m: float
    sigma_m: float
    surface_z_m: float
    x_m: float
    y_m: float
    t_s: float
    samples: int
    bias_N: float
    speed_m_per_s: float
    raw_offset_m: float
    kappa_scale: float

    def as_dict(self) -> dict:
        return dict(self._asdict())


def tip_velocity(t_s, z_m, index, half_window_s=VELOCITY_HALF_WINDOW_S) -> np.ndarray:
    """Least-squares slope of z over t within +-half_window_s of each index, m/s."""
    t = np.asarray(t_s, float)
    z = np.asarray(z_m, float)
    out = np.empty(len(index))
    lo = np.searchsorted(t, t[index] - half_window_s, side="left")
    hi = np.searchsorted(t, t[index] + half_window_s, side="right")
    for k, (a, b) in enumerate(zip(lo, hi)):
        tt, zz = t[a:b], z[a:b]
        if tt.size < 2:
            out[k] = np.nan
            continue
        tc = tt - tt.mean()
        out[k] = float(np.dot(tc, zz - zz.mean()) / np.dot(tc, tc))
    return out


def _line_zero(z, w):
    """Zero of the least-squares line w(z) and its 1-sigma; None if w does not fall as z rises."""
    (slope, icpt), cov = np.polyfit(z, w, 1, cov=True)
    if not slope < 0:
        return None
    grad = np.array([icpt / slope**2, -1.0 / slope])
    return -icpt / slope, float(np.sqrt(max(grad @ cov @ grad, 0.0))), float(-slope)


def lift_off_offset(
    df: pd.DataFrame,
    phantom,
    *,
    relaxation=DEFAULT_RELAXATION,
    viscous: bool = True,
    history_offset_m=None,
    high_N: float = ONSET_HIGH_N,
) -> LiftOff | None:
    """The surface at a log's final lift-off; None without one.

    Needs :data:`~vic_drake.analysis.surface_offset.MIN_FREE_S` of record out
    of contact after the last contact (the bias and noise are read there, from
    :data:`~vic_drake.analysis.surface_offset.FREE_MARGIN_S` after it). The
    fit runs over the force's final fall, from its last sample above
    ``high_N`` to its last above max(ONSET_LOW_N, ONSET_NOISE_Z sigma), both
    above the bias (see the module doc for the model).

    Args:
        df: canonical scan frame (t_s, x_m, y_m, z_m, force_sensor_z_N).
        phantom: the map (surface, slope, kappa, lam, beta), which the
            controller read; the surface found is against it.
        relaxation: the tissue's :class:`~vic_drake.tissue.relaxation.RelaxationParams`,
            None for plain Hunt-Crossley.
        viscous: correct for the viscous term (False only to measure it).
        history_offset_m: the surface over the scan against the map, for the
            relaxation states: a float, one value per sample of ``df``, or
            None (the estimate itself, :data:`HISTORY_PASSES` passes).
        high_N: start of the fit above the bias, N (> ONSET_LOW_N).

    Returns:
        :class:`LiftOff`, or None when the log ends in contact (or too soon
        after), or the fall is too short, does not rise, or is all viscous.
    """
    require_columns(df, "t_s", "x_m", "y_m", "z_m", "force_sensor_z_N")
    if not (np.isfinite(high_N) and high_N > ONSET_LOW_N):
        raise VicDrakeError(
            f"high_N must be a number of N above {ONSET_LOW_N}; got {high_N!r}"
        )
    t = df["t_s"].to_numpy(float)
    x, y, z = (df[c].to_numpy(float) for c in ("x_m", "y_m", "z_m"))
    if history_offset_m is not None:
        history = np.broadcast_to(np.asarray(history_offset_m, float), t.shape)
        if not np.all(np.isfinite(history)):
            raise VicDrakeError("history_offset_m must be finite (m)")
    f = pressing_force_N(df)
    over = np.flatnonzero(f > CONTACT_THRESHOLD_N)
    if over.size == 0:
        return None
    free = t > t[over[-1]] + FREE_MARGIN_S
    if free.sum() < 3 or t[-1] - t[free][0] < MIN_FREE_S:
        return None
    bias = float(np.median(f[free]))
    noise = float(np.std(np.diff(f[free])) / np.sqrt(2.0))
    low = max(ONSET_LOW_N, ONSET_NOISE_Z * noise)
    rel = f - bias
    end = int(np.flatnonzero(free)[0])
    above_low = np.flatnonzero(rel[:end] > low)
    if above_low.size == 0:
        return None
    i1 = int(above_low[-1]) + 1
    above_high = np.flatnonzero(rel[:i1] > high_N)
    if above_high.size == 0:
        return None
    i0 = int(above_high[-1]) + 1
    if i1 - i0 < MIN_ONSET_SAMPLES:
        return None
    idx = np.arange(i0, i1)
    if not all(np.all(np.isfinite(a[idx])) for a in (x, y, z, rel)):
        return None
    tissue = phantom.sample(x[idx], y[idx])
    kappa = np.asarray(tissue.kappa, float)
    ratio = np.asarray(tissue.lam, float) / kappa
    vz = tip_velocity(t, z, idx)
    vx, vy = tip_velocity(t, x, idx), tip_velocity(t, y, idx)
    # Penetration rate of a stationary tissue (the element's chain rule).
    eps_dot = np.asarray(tissue.dz_dx) * vx + np.asarray(tissue.dz_dy) * vy - vz
    factor = 1.0 + ratio * eps_dot if viscous else np.ones(idx.size)
    beta = phantom.beta
    raw = _line_zero(z[idx], np.maximum(rel[idx], 0.0) ** (1.0 / beta))
    usable = np.isfinite(factor) & (factor > MIN_VISCOUS_FACTOR)
    if raw is None or usable.sum() < MIN_ONSET_SAMPLES:
        return None
    elastic = np.maximum(rel[idx], 0.0) / kappa
    map_all = np.asarray(phantom.surface_z(x, y), float)

    def fit(offsets):
        relaxed = 0.0
        if relaxation is not None and relaxation.n_branches:
            u = relaxation_input(map_all + offsets - z, beta)
            states = relaxation_history(t, u, relaxation.time_constants_s)
            relaxed = states[idx] @ np.asarray(relaxation.fractions)
        w = ((elastic + relaxed) / np.where(usable, factor, 1.0)) ** (1.0 / beta)
        return _line_zero(z[idx][usable], w[usable])

    leave = int(idx[-1])
    map_z = float(map_all[leave])
    if history_offset_m is not None:
        found = fit(history)
    else:
        guess = raw[0] - map_z  # first pass: the uncorrected surface
        for _ in range(HISTORY_PASSES):
            found = fit(np.full(t.shape, guess))
            if found is None:
                break
            guess = found[0] - map_z
    if found is None:
        return None
    surface, sigma, slope = found
    return LiftOff(
        offset_m=float(surface - map_z),
        sigma_m=sigma,
        surface_z_m=float(surface),
        x_m=float(x[leave]),
        y_m=float(y[leave]),
        t_s=float(t[leave]),
        samples=int(usable.sum()),
        bias_N=bias,
        speed_m_per_s=float(np.median(vz)),
        raw_offset_m=float(raw[0] - map_z),
        kappa_scale=float(slope**beta),
    )


__all__ = [
    "HISTORY_PASSES",
    "MIN_VISCOUS_FACTOR",
    "VELOCITY_HALF_WINDOW_S",
    "LiftOff",
    "lift_off_offset",
    "tip_velocity",
]
