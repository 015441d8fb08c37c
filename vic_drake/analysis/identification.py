"""Identification from scan logs: the FDCC force-loop gain, the tissue's
lateral friction and normal tilt, and the phantom's lift under a disturbance
(:mod:`vic_drake.analysis.phantom_motion`).
"""

import numpy as np
import pandas as pd
from scipy.signal import savgol_filter

from vic_drake.analysis.columns import require_columns
from vic_drake.analysis.contact import contact_mask, pressing_force_N
from vic_drake.analysis.phantom_motion import estimate_phantom_motion, lift_table

__all__ = [
    "estimate_force_loop_gain",
    "estimate_phantom_lift",
    "estimate_tissue_friction",
    "lift_table",
]


def _smoothed_rate(t: np.ndarray, v: np.ndarray, smooth_s: float) -> np.ndarray:
    """d v / d t after a cubic Savitzky-Golay smoothing over about smooth_s."""
    dt = float(np.median(np.diff(t)))
    window = max(5, int(round(smooth_s / dt)) | 1)
    return np.gradient(savgol_filter(v, window, 3), t)


def estimate_force_loop_gain(
    df: pd.DataFrame,
    *,
    stiffness_z_N_per_m: float | None = None,
    force_ref_z_N: float | None = None,
    smooth_s: float = 0.1,
) -> dict:
    """Identifies the z loop gain of the FDCC layer from a scan, m/s per N.

    FDCC integrates the net Cartesian error: in quasi-steady motion the tip's
    z velocity is proportional to the net z error,
    ``z' = G (K_z (z_d - z) + f_ref - f_m)`` (sensor convention, f negative
    = pressing), with G set by the PD gain k_p, ``error_scale``, the internal
    model and the arm's position servo. G is the least-squares slope (with an
    intercept, which absorbs a constant force bias) of the smoothed z velocity
    against that error over the contact samples. The 9-column logs hold
    neither K_z nor f_ref: pass the run's constants.

    Args:
        df: canonical scan frame (t_s, z_m, z_d_m, force_sensor_z_N; and
            stiffness_z_N_per_m / force_ref_z_N when not given).
        stiffness_z_N_per_m: constant K_z, N/m (default: the frame's column).
        force_ref_z_N: constant target force, sensor convention, N (default:
            the frame's column).
        smooth_s: Savitzky-Golay window of the velocity, s.

    Returns:
        dict with ``gain_m_per_s_per_N``, ``r2`` (of the linear model),
        ``offset_N`` (the constant error the intercept absorbed: the fit is
        ``z' = G (error - offset)``) and ``samples``; the
        figures are NaN when fewer than 100 contact samples exist.
    """
    require_columns(df, "t_s", "z_m", "z_d_m", "force_sensor_z_N")
    t = df["t_s"].to_numpy(float)
    z = df["z_m"].to_numpy(float)
    f = df["force_sensor_z_N"].to_numpy(float)
    if stiffness_z_N_per_m is None:
        require_columns(df, "stiffness_z_N_per_m")
        k = df["stiffness_z_N_per_m"].to_numpy(float)
    else:
        k = np.full(len(df), float(stiffness_z_N_per_m))
    if force_ref_z_N is None:
        require_columns(df, "force_ref_z_N")
        f_ref = df["force_ref_z_N"].to_numpy(float)
    else:
        f_ref = np.full(len(df), float(force_ref_z_N))
    nan = {"gain_m_per_s_per_N": np.nan, "r2": np.nan, "offset_N": np.nan, "samples": 0}
    if len(t) < 100:
        return nan
    vz = _smoothed_rate(t, z, smooth_s)
    net = k * (df["z_d_m"].to_numpy(float) - z) + f_ref - f
    use = contact_mask(df) & np.isfinite(net) & np.isfinite(vz)
    n = int(use.sum())
    if n < 100 or np.ptp(net[use]) == 0:
        return {**nan, "samples": n}
    a = np.column_stack([net[use], np.ones(n)])
    (gain, intercept), *_ = np.linalg.lstsq(a, vz[use], rcond=None)
    resid = vz[use] - a @ np.array([gain, intercept])
    r2 = 1.0 - float(resid.var() / vz[use].var())
    offset = -intercept / gain if gain != 0 else np.nan
    return {
        "gain_m_per_s_per_N": float(gain),
        "r2": r2,
        "offset_N": float(offset),
        "samples": n,
    }


def estimate_tissue_friction(
    df: pd.DataFrame,
    phantom,
    *,
    slip_speed_m_per_s: float = 0.005,
    min_speed_m_per_s: float = 0.005,
    min_force_N: float = 3.0,
    smooth_s: float = 0.1,
) -> dict:
    """Identifies the direction of the tissue force and its sliding friction.

    Model of the external force on the probe in W while it slides over the
    tissue with horizontal velocity v (the tissue force element's,
    :func:`vic_drake.systems.tissue_force.tip_contact`):
    ``f = F (-a dz/dx, -a dz/dy, 1) - mu F v / sqrt(|v|^2 + v_s^2)``, with F
    the vertical (pressing) force, ``a`` the tilt (1 = along the surface
    normal, 0 = vertical) and mu the friction coefficient. The sensor's x, y
    columns are minus the external force in W (the canonical convention),
    so ``(-f_x, -f_y)`` is regressed jointly on
    the two terms over the samples that press harder than ``min_force_N`` and
    slide faster than ``min_speed_m_per_s``. Use nominal scans (a lifted
    phantom moves its surface).

    Args:
        df: canonical scan frame with t_s, x_m, y_m and the sensor's
            force_sensor_{x,y,z}_N (31-column real logs through
            real_to_canonical, or simulated runs).
        phantom: the tissue map in W (surface_gradient).
        slip_speed_m_per_s: v_s of the friction law.
        min_speed_m_per_s, min_force_N: sample selection.
        smooth_s: Savitzky-Golay window of the velocity, s.

    Returns:
        dict with ``tilt`` (a), ``friction_coefficient`` (mu), ``r2`` and
        ``samples``; NaN figures when fewer than 100 samples qualify.
    """
    require_columns(
        df,
        "t_s",
        "x_m",
        "y_m",
        "force_sensor_x_N",
        "force_sensor_y_N",
        "force_sensor_z_N",
    )
    nan = {"tilt": np.nan, "friction_coefficient": np.nan, "r2": np.nan, "samples": 0}
    t = df["t_s"].to_numpy(float)
    if len(t) < 100:
        return nan
    x, y = df["x_m"].to_numpy(float), df["y_m"].to_numpy(float)
    vx, vy = _smoothed_rate(t, x, smooth_s), _smoothed_rate(t, y, smooth_s)
    force = pressing_force_N(df)
    fx_w = -df["force_sensor_x_N"].to_numpy(float)  # External force in W.
    fy_w = -df["force_sensor_y_N"].to_numpy(float)
    use = (force > min_force_N) & (np.hypot(vx, vy) > min_speed_m_per_s)
    use &= np.isfinite(fx_w) & np.isfinite(fy_w)
    n = int(use.sum())
    if n < 100:
        return {**nan, "samples": n}
    gx, gy = (np.asarray(g, float) for g in phantom.surface_gradient(x[use], y[use]))
    f, vx, vy = force[use], vx[use], vy[use]
    scale = f / np.sqrt(vx * vx + vy * vy + slip_speed_m_per_s**2)
    a = np.column_stack([np.r_[-gx * f, -gy * f], np.r_[-scale * vx, -scale * vy]])
    b = np.r_[fx_w[use], fy_w[use]]
    (tilt, mu), *_ = np.linalg.lstsq(a, b, rcond=None)
    resid = b - a @ np.array([tilt, mu])
    return {
        "tilt": float(tilt),
        "friction_coefficient": float(mu),
        "r2": 1.0 - float(resid.var() / b.var()),
        "samples": n,
    }


def estimate_phantom_lift(
    dist: pd.DataFrame,
    phantom,
    *,
    nominal: pd.DataFrame | None = None,
    smooth_s: float = 0.2,
    baseline_s: float = 1.0,
) -> pd.DataFrame:
    """The phantom's vertical motion of a scan (t_s, phantom_lift_m, measured).

    The columns of :func:`vic_drake.analysis.phantom_motion.estimate_phantom_motion`
    without its uncertainty; see there for the method.
    """
    motion = estimate_phantom_motion(
        dist, phantom, nominal=nominal, smooth_s=smooth_s, baseline_s=baseline_s
    )
    return motion[["t_s", "phantom_lift_m", "measured"]]
