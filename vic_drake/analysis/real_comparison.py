"""A simulated scan against the real log of the same experiment.

Alignment in time (bounded cross-correlation), the sensor's force lead of
the 9-column logs, and the comparison metrics over the real scan window.
"""

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import CANONICAL_COLUMNS, require_columns
from vic_drake.analysis.contact import (
    contact_loss_intervals,
    pressing_force_N,
    scan_window,
)
from vic_drake.analysis.scan_metrics import peak_force_N, tank_min_J
from vic_drake.errors import VicDrakeError

#: The keys that `vic-drake compare-real` always prints first, in this order
#: (its JSON contract); the reproduce report shows the same.
COMPARE_REAL_KEYS = (
    "controller",
    "duration_s",
    "force_rmse_N",
    "force_peak_err_N",
    "z_rmse_mm",
    "kz_corr",
    "tank_min_J",
    "rtf",
)


def resample(df: pd.DataFrame, t_s: np.ndarray, columns) -> dict[str, np.ndarray]:
    """Linear interpolation of columns at times t_s (NaN outside the record)."""
    t = df["t_s"].to_numpy(float)
    out = {}
    for c in columns:
        v = df[c].to_numpy(float)
        good = np.isfinite(v)
        if good.sum() < 2:
            out[c] = np.full(len(t_s), np.nan)
            continue
        r = np.interp(t_s, t[good], v[good], left=np.nan, right=np.nan)
        out[c] = r
    return out


def estimate_time_offset_s(
    sim: pd.DataFrame,
    real: pd.DataFrame,
    *,
    column: str = "force_sensor_z_N",
    max_lag_s: float = 0.5,
    dt_s: float = 0.01,
) -> float:
    """Shift (s) to add to the simulated time to best match the real log.

    Both records are resampled at dt_s over their overlap, demeaned, and the
    lag in [-max_lag_s, max_lag_s] maximising their cross-correlation is
    returned. The bound keeps the alignment from trading a real mismatch
    for a shift: both runs follow the same target on the same clock, so
    only the reaction lags (sensor filter, contact onset) can differ.
    """
    t0 = max(sim["t_s"].iloc[0], real["t_s"].iloc[0])
    t1 = min(sim["t_s"].iloc[-1], real["t_s"].iloc[-1])
    if t1 - t0 < 4 * max_lag_s:
        return 0.0
    grid = np.arange(t0, t1, dt_s)
    a = resample(sim, grid, [column])[column]
    b = resample(real, grid, [column])[column]
    a = np.nan_to_num(a - np.nanmean(a))
    b = np.nan_to_num(b - np.nanmean(b))
    n_lag = int(round(max_lag_s / dt_s))
    best, best_lag = -np.inf, 0
    for k in range(-n_lag, n_lag + 1):
        if k >= 0:
            c = np.dot(a[: len(a) - k], b[k:])
        else:
            c = np.dot(a[-k:], b[: len(b) + k])
        if c > best:
            best, best_lag = c, k
    return best_lag * dt_s


def shift_time(df: pd.DataFrame, offset_s: float) -> pd.DataFrame:
    """A copy of df with t_s + offset_s."""
    out = df.copy()
    out["t_s"] = out["t_s"] + offset_s
    return out


def lead_force(df: pd.DataFrame, lead_s: float) -> pd.DataFrame:
    """A copy whose force columns are advanced by lead_s (value at t + lead_s).

    The 9-column CS/CF logs store each pose with the force read 28 ticks
    later, which undoes the sensor's lag; a simulated sensor with that lag is
    put on the same footing by advancing its force by the same time.
    """
    if lead_s == 0:
        return df
    out = df.copy()
    t = df["t_s"].to_numpy(float)
    for c in ("force_sensor_x_N", "force_sensor_y_N", "force_sensor_z_N"):
        v = df[c].to_numpy(float)
        out[c] = np.interp(t + lead_s, t, v, right=np.nan)
    return out


def compare_with_real(
    sim: pd.DataFrame,
    real: pd.DataFrame,
    *,
    align: bool = True,
    max_lag_s: float = 0.5,
    force_lead_s: float = 0.0,
) -> dict:
    """Metrics of a simulated scan against the real log of the same experiment.

    The simulated force is first advanced by ``force_lead_s`` (see
    :func:`lead_force`; 0 for the 31-column logs, whose force is the raw,
    lagged sensor reading like the simulated one). The simulated record is
    then shifted by :func:`estimate_time_offset_s` (when ``align``),
    resampled at the real log's times over the real scan window
    (:func:`vic_drake.analysis.contact.scan_window` of the real log), and
    compared there.

    Returns:
        dict with force_rmse_N (sensor z force, sim vs real), force_peak_err_N
        (|peak pressing force sim - real| over their common time span), z_rmse_mm,
        kz_corr (Pearson correlation of K_z over the window; None when the
        real log has no K_z or either record is constant), time_offset_s,
        window_s (start, end), force_peak_sim_N, force_peak_real_N,
        force_mean_sim_N, force_mean_real_N, tank_min_J (sim),
        tank_min_real_J (None if not logged).
    """
    require_columns(sim, *CANONICAL_COLUMNS[:10])
    require_columns(
        real, "t_s", "z_m", "force_sensor_z_N", "stiffness_z_N_per_m", "tank_energy_J"
    )
    sim = lead_force(sim, force_lead_s)
    offset = estimate_time_offset_s(sim, real, max_lag_s=max_lag_s) if align else 0.0
    sim_s = shift_time(sim, offset)
    window = scan_window(real)
    t = real["t_s"].to_numpy(float)
    cols = ["force_sensor_z_N", "z_m", "stiffness_z_N_per_m"]
    s = resample(sim_s, t, cols)
    valid = window & np.isfinite(s["force_sensor_z_N"])
    if valid.sum() < 10:
        raise VicDrakeError(
            "the simulated and real scans do not overlap in the real log's contact window; "
            "simulate longer or check the scenario"
        )
    f_err = (
        s["force_sensor_z_N"][valid] - real["force_sensor_z_N"].to_numpy(float)[valid]
    )
    z_err = s["z_m"][valid] - real["z_m"].to_numpy(float)[valid]
    k_real = real["stiffness_z_N_per_m"].to_numpy(float)[valid]
    k_sim = s["stiffness_z_N_per_m"][valid]
    kz_corr = None
    ok = np.isfinite(k_real) & np.isfinite(k_sim)
    if ok.sum() > 10 and np.std(k_real[ok]) > 0 and np.std(k_sim[ok]) > 0:
        kz_corr = float(np.corrcoef(k_real[ok], k_sim[ok])[0, 1])
    # Peaks over the common time span (a shortened simulation is not charged
    # with the peaks of the log it did not reach).
    t_lo = max(float(sim_s["t_s"].iloc[0]), float(t[0]))
    t_hi = min(float(sim_s["t_s"].iloc[-1]), float(t[-1]))
    in_sim = (sim_s["t_s"] >= t_lo) & (sim_s["t_s"] <= t_hi)
    in_real = (real["t_s"] >= t_lo) & (real["t_s"] <= t_hi)
    peak_sim, peak_real = peak_force_N(sim_s[in_sim]), peak_force_N(real[in_real])
    tank_real = tank_min_J(real)
    return {
        "force_rmse_N": float(np.sqrt(np.mean(f_err**2))),
        "force_peak_err_N": float(abs(peak_sim - peak_real)),
        "z_rmse_mm": float(1e3 * np.sqrt(np.mean(z_err**2))),
        "kz_corr": kz_corr,
        "time_offset_s": float(offset),
        "force_lead_s": float(force_lead_s),
        "window_s": [float(t[valid][0]), float(t[valid][-1])],
        "force_peak_sim_N": peak_sim,
        "force_peak_real_N": peak_real,
        "force_mean_sim_N": float(np.mean(-s["force_sensor_z_N"][valid])),
        "force_mean_real_N": float(np.mean(pressing_force_N(real)[valid])),
        "tank_min_J": tank_min_J(sim),
        "tank_min_real_J": None if not np.isfinite(tank_real) else tank_real,
    }


def compare_contact_loss(sim: pd.DataFrame, real: pd.DataFrame) -> dict:
    """Contact-loss intervals of both runs and how they overlap (disturbance runs).

    Returns:
        dict: contact_loss_sim_s, contact_loss_real_s (lists of [t0, t1]),
        contact_loss_total_sim_s, contact_loss_total_real_s (summed
        durations), contact_loss_overlap_s (time lost in both).
    """
    a = contact_loss_intervals(sim)
    b = contact_loss_intervals(real)
    overlap = 0.0
    for a0, a1 in a:
        for b0, b1 in b:
            overlap += max(0.0, min(a1, b1) - max(a0, b0))
    return {
        "contact_loss_sim_s": [list(i) for i in a],
        "contact_loss_real_s": [list(i) for i in b],
        "contact_loss_total_sim_s": float(sum(i1 - i0 for i0, i1 in a)),
        "contact_loss_total_real_s": float(sum(i1 - i0 for i0, i1 in b)),
        "contact_loss_overlap_s": float(overlap),
    }
