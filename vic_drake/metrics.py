"""Scan metrics, shared by simulated runs and the real logs.

Every function takes a DataFrame in the *canonical* scan layout
(:data:`CANONICAL_COLUMNS`, what :func:`vic_drake.experiments.run_scan`
returns). Real bags are converted to it with :func:`real_to_canonical` (signals
the real log does not hold become NaN), so real and simulated scans go through
the same functions.

Sign convention: ``force_sensor_{x,y,z}_N`` are the sensor's reading in W,
minus the external force on the probe (the force the probe exerts), so
``force_sensor_z_N`` is negative when pressing into the body; "pressing
force" below means ``-force_sensor_z_N``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from vic_drake.errors import VicDrakeError

#: The columns of a scan DataFrame (interfaces.md, "D2").
CANONICAL_COLUMNS = (
    "t_s",
    "x_m",
    "y_m",
    "z_m",
    "x_d_m",
    "y_d_m",
    "z_d_m",
    "force_sensor_x_N",
    "force_sensor_y_N",
    "force_sensor_z_N",
    "force_tissue_z_N",
    "penetration_m",
    "surface_z_m",
    "phantom_lift_m",
    "force_ref_z_N",
    "force_min_z_N",
    "stiffness_x_N_per_m",
    "stiffness_y_N_per_m",
    "stiffness_z_N_per_m",
    "tank_energy_J",
    "tank_power_W",
    "tank_sigma",
    "tank_enabled",
    "qp_ok",
    "in_contact",
    *(f"q_cmd_{i}_rad" for i in range(6)),
)

#: Contact threshold on the pressing force, N. The real controller declared
#: contact when the sensor's z force was below -0.5 N (data README), which is
#: about 5 times the sensor's noise floor in the free-motion parts of the logs.
CONTACT_THRESHOLD_N = 0.5

#: Shortest contact loss that counts, s. 25 ticks at 500 Hz: shorter dips
#: under the threshold are sensor noise around 0.5 N, not a lost contact.
MIN_CONTACT_LOSS_S = 0.05

#: kappa above which a point counts as "over a rib", N/m^beta. The measured
#: map's soft tissue lies at 2,000-5,500 and its rib lines reach 9,000-10,236;
#: 7,000 sits in the gap between the two populations of the histogram.
RIB_KAPPA_THRESHOLD = 7000.0

#: Time skipped after the first contact before force errors are scored, s.
#: The impact transient (first ~0.5 s of contact in every real log) depends
#: on the approach speed and the sensor's filter, not on the scan behaviour
#: the comparison is about; 1 s covers it with margin.
SETTLE_S = 1.0


def _require(df: pd.DataFrame, *columns: str) -> None:
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise VicDrakeError(
            f"scan DataFrame lacks columns {missing}; expected the canonical layout "
            "(vic_drake.metrics.CANONICAL_COLUMNS)"
        )


def real_to_canonical(df: pd.DataFrame) -> pd.DataFrame:
    """Converts a real bag (``realdata.read_bag``) to the canonical scan layout.

    - 31-column controller logs: every canonical signal the controller logged
      (the sensor's x force negated: see the code);
      ``surface_z_m`` = penetration + z (the map surface under the probe),
      ``tank_power_W`` = dT / dt; ``force_tissue_z_N`` is NaN (not measured).
    - 9-column CS/CF logs: pose, target z (x_d, y_d NaN) and the sensor's z
      force (= minus the logged pressing force).

    Raises:
        VicDrakeError: a layout other than "controller" or "scan".
    """
    layout = df.attrs.get("layout")
    n = len(df)
    out = pd.DataFrame({c: np.full(n, np.nan) for c in CANONICAL_COLUMNS})
    out["t_s"] = df["t_s"].to_numpy()
    if layout == "controller":
        same = {
            "x_m": "x_m", "y_m": "y_m", "z_m": "z_m",
            "x_d_m": "x_d_m", "y_d_m": "y_d_m", "z_d_m": "z_d_m",
            "force_sensor_x_N": "sensor_force_x_N",
            "force_sensor_y_N": "sensor_force_y_N",
            "force_sensor_z_N": "sensor_force_z_N",
            "penetration_m": "penetration_m",
            "force_ref_z_N": "force_ref_z_N",
            "force_min_z_N": "force_min_z_N",
            "stiffness_x_N_per_m": "stiffness_x_N_per_m",
            "stiffness_y_N_per_m": "stiffness_y_N_per_m",
            "stiffness_z_N_per_m": "stiffness_z_N_per_m",
            "tank_energy_J": "tank_energy_J",
        }  # fmt: skip
        for dst, src in same.items():
            out[dst] = df[src].to_numpy()
        # The logged x, y forces are the external force on the probe in the
        # sensor frame S (x_S = x_W, y_S = -y_W with the tool pointing down;
        # estimate_tissue_friction finds the normal tilt and friction
        # consistent in both axes only so); the canonical reading is minus
        # the external force in W, as the simulated sensor's: x flips.
        out["force_sensor_x_N"] = -df["sensor_force_x_N"].to_numpy()
        out["surface_z_m"] = df["penetration_m"].to_numpy() + df["z_m"].to_numpy()
        dt = np.gradient(df["t_s"].to_numpy())
        out["tank_power_W"] = df["tank_delta_J"].to_numpy() / np.where(
            dt > 0, dt, np.nan
        )
        out["in_contact"] = (
            df["sensor_force_z_N"].to_numpy() < -CONTACT_THRESHOLD_N
        ).astype(float)
        out["phantom_lift_m"] = 0.0
    elif layout == "scan":
        for c in ("x_m", "y_m", "z_m"):
            out[c] = df[c].to_numpy()
        out["z_d_m"] = df["z_target_m"].to_numpy()
        out["force_sensor_z_N"] = -df["force_pressing_z_N"].to_numpy()
        out["in_contact"] = (
            df["force_pressing_z_N"].to_numpy() > CONTACT_THRESHOLD_N
        ).astype(float)
    else:
        raise VicDrakeError(
            f"real_to_canonical takes a scan log ('controller' 31-column or 'scan' 9-column "
            f"layout); got layout {layout!r}"
        )
    out.attrs.update(df.attrs)
    out.attrs["source"] = "real"
    return out


def pressing_force_N(df: pd.DataFrame) -> np.ndarray:
    """Pressing force, N (positive = pushing into the body)."""
    _require(df, "force_sensor_z_N")
    return -df["force_sensor_z_N"].to_numpy(dtype=float)


def contact_mask(
    df: pd.DataFrame, threshold_N: float = CONTACT_THRESHOLD_N
) -> np.ndarray:
    """True where the pressing force exceeds the contact threshold."""
    return pressing_force_N(df) > threshold_N


def scan_window(
    df: pd.DataFrame,
    *,
    settle_s: float = SETTLE_S,
    threshold_N: float = CONTACT_THRESHOLD_N,
) -> np.ndarray:
    """Samples of the scan proper: from first contact + settle_s to last contact.

    Returns an all-False mask when the probe never touched.
    """
    t = df["t_s"].to_numpy(dtype=float)
    contact = contact_mask(df, threshold_N)
    if not contact.any():
        return np.zeros(len(df), bool)
    t_first = t[np.argmax(contact)]
    t_last = t[len(contact) - 1 - np.argmax(contact[::-1])]
    return (t >= t_first + settle_s) & (t <= t_last)


def force_rmse_N(df: pd.DataFrame, *, mask=None) -> float:
    """RMS of (measured - reference) z force over the mask (default: scan window), N.

    The reference is ``force_ref_z_N``; samples where it is NaN are skipped.
    """
    _require(df, "force_sensor_z_N", "force_ref_z_N")
    mask = scan_window(df) if mask is None else np.asarray(mask, bool)
    err = df["force_sensor_z_N"].to_numpy(float) - df["force_ref_z_N"].to_numpy(float)
    err = err[mask & np.isfinite(err)]
    return float(np.sqrt(np.mean(err**2))) if err.size else float("nan")


def force_range_N(df: pd.DataFrame, *, mask=None) -> tuple[float, float]:
    """(min, max) pressing force over the mask (default: scan window), N."""
    mask = scan_window(df) if mask is None else np.asarray(mask, bool)
    f = pressing_force_N(df)[mask]
    return (float(f.min()), float(f.max())) if f.size else (float("nan"), float("nan"))


def peak_force_N(df: pd.DataFrame) -> float:
    """Largest pressing force of the whole run, N."""
    return float(np.nanmax(pressing_force_N(df)))


def tank_min_J(df: pd.DataFrame) -> float:
    """Lowest tank energy of the run, J (NaN if the tank is not logged)."""
    _require(df, "tank_energy_J")
    e = df["tank_energy_J"].to_numpy(float)
    return float(np.nanmin(e)) if np.isfinite(e).any() else float("nan")


def contact_loss_intervals(
    df: pd.DataFrame,
    *,
    threshold_N: float = CONTACT_THRESHOLD_N,
    min_duration_s: float = MIN_CONTACT_LOSS_S,
) -> list[tuple[float, float]]:
    """Intervals (t_start, t_end) without contact between first and last contact, s.

    A loss shorter than ``min_duration_s`` is ignored (see MIN_CONTACT_LOSS_S).
    The free motion before the first touch and after the final lift-off are
    not losses.
    """
    t = df["t_s"].to_numpy(float)
    contact = contact_mask(df, threshold_N)
    if not contact.any():
        return []
    i0 = int(np.argmax(contact))
    i1 = len(contact) - 1 - int(np.argmax(contact[::-1]))
    intervals = []
    start = None
    for i in range(i0, i1 + 1):
        if not contact[i] and start is None:
            start = i
        elif contact[i] and start is not None:
            if t[i] - t[start] >= min_duration_s:
                intervals.append((float(t[start]), float(t[i])))
            start = None
    return intervals


@dataclass(frozen=True)
class PenetrationStats:
    """Penetration (m) in contact over ribs and off ribs.

    Attributes:
        rib_mean_m, rib_max_m: over samples whose kappa exceeds the rib threshold.
        soft_mean_m, soft_max_m: over the other samples in contact.
        rib_samples, soft_samples: sample counts.
    """

    rib_mean_m: float
    rib_max_m: float
    soft_mean_m: float
    soft_max_m: float
    rib_samples: int
    soft_samples: int


def penetration_stats(
    df: pd.DataFrame, phantom, *, rib_kappa_threshold: float = RIB_KAPPA_THRESHOLD
) -> PenetrationStats:
    """Penetration on ribs vs off ribs over the scan window (see RIB_KAPPA_THRESHOLD).

    Args:
        df: canonical scan; uses x_m, y_m, penetration_m (NaN rows skipped).
        phantom: a :class:`vic_drake.tissue.phantom.Phantom` giving kappa(x, y).
    """
    _require(df, "x_m", "y_m", "penetration_m")
    mask = scan_window(df)
    kappa = np.asarray(
        phantom.kappa(df["x_m"].to_numpy(float), df["y_m"].to_numpy(float))
    )
    pen = df["penetration_m"].to_numpy(float)
    ok = mask & np.isfinite(pen)
    rib = ok & (kappa > rib_kappa_threshold)
    soft = ok & ~(kappa > rib_kappa_threshold)

    def stats(sel):
        if not sel.any():
            return float("nan"), float("nan")
        return float(np.mean(pen[sel])), float(np.max(pen[sel]))

    rm, rx = stats(rib)
    sm, sx = stats(soft)
    return PenetrationStats(rm, rx, sm, sx, int(rib.sum()), int(soft.sum()))


def liftoff_clearance_m(df: pd.DataFrame, *, tail_s: float = 0.5) -> float:
    """Mean gap between tip and surface over the last tail_s of the run, m.

    Positive = the probe left the surface. NaN where the surface is not known.
    """
    _require(df, "t_s", "penetration_m")
    t = df["t_s"].to_numpy(float)
    tail = t >= t[-1] - tail_s
    pen = df["penetration_m"].to_numpy(float)[tail]
    return float(-np.nanmean(pen)) if np.isfinite(pen).any() else float("nan")


def lifted_off(
    df: pd.DataFrame, *, tail_s: float = 0.5, threshold_N: float = CONTACT_THRESHOLD_N
) -> bool:
    """True when the probe is out of contact over the last tail_s of the run."""
    t = df["t_s"].to_numpy(float)
    tail = t >= t[-1] - tail_s
    return bool(not contact_mask(df, threshold_N)[tail].any())


# --------------------------------------------------------------------------
# Comparison of a simulated scan with a real log.


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
    (:func:`scan_window` of the real log: first contact + SETTLE_S to last
    contact), and compared there.

    Returns:
        dict with force_rmse_N (sensor z force, sim vs real), force_peak_err_N
        (|peak pressing force sim - real| over their common time span), z_rmse_mm,
        kz_corr (Pearson correlation of K_z over the window; None when the
        real log has no K_z or either record is constant), time_offset_s,
        window_s (start, end), force_peak_sim_N, force_peak_real_N,
        force_mean_sim_N, force_mean_real_N, tank_min_J (sim),
        tank_min_real_J (None if not logged).
    """
    _require(sim, *CANONICAL_COLUMNS[:10])
    _require(
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


# --------------------------------------------------------------------------
# Phantom lift of the real disturbance logs.


def _smoothed_rate(t: np.ndarray, v: np.ndarray, smooth_s: float) -> np.ndarray:
    """d v / d t after a cubic Savitzky-Golay smoothing over about smooth_s."""
    from scipy.signal import savgol_filter

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
    _require(df, "t_s", "z_m", "z_d_m", "force_sensor_z_N")
    t = df["t_s"].to_numpy(float)
    z = df["z_m"].to_numpy(float)
    f = df["force_sensor_z_N"].to_numpy(float)
    if stiffness_z_N_per_m is None:
        _require(df, "stiffness_z_N_per_m")
        k = df["stiffness_z_N_per_m"].to_numpy(float)
    else:
        k = np.full(len(df), float(stiffness_z_N_per_m))
    if force_ref_z_N is None:
        _require(df, "force_ref_z_N")
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
    _require(df, "t_s", "x_m", "y_m", "force_sensor_x_N", "force_sensor_y_N",
             "force_sensor_z_N")
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
    a = np.column_stack(
        [np.r_[-gx * f, -gy * f], np.r_[-scale * vx, -scale * vy]]
    )
    b = np.r_[fx_w[use], fy_w[use]]
    (tilt, mu), *_ = np.linalg.lstsq(a, b, rcond=None)
    resid = b - a @ np.array([tilt, mu])
    return {
        "tilt": float(tilt),
        "friction_coefficient": float(mu),
        "r2": 1.0 - float(resid.var() / b.var()),
        "samples": n,
    }


def apparent_surface_z_m(df: pd.DataFrame, phantom) -> np.ndarray:
    """Surface height implied by the tip height and the pressing force, m.

    Inverts the static Hunt-Crossley law F = kappa eps^beta with kappa of the
    phantom map at the tip's (x, y): surface = z + (F / kappa)^(1 / beta).
    NaN out of contact (no force, no information on the surface). The
    viscous term is neglected: at the logs' penetration rates (|eps_dot| <
    3 cm/s) it changes eps by under 1 mm on soft tissue.
    """
    f = pressing_force_N(df)
    x, y = df["x_m"].to_numpy(float), df["y_m"].to_numpy(float)
    kappa = np.asarray(phantom.kappa(x, y), float)
    eps = np.where(f > CONTACT_THRESHOLD_N, np.maximum(f, 0.0) / kappa, np.nan) ** (
        1.0 / phantom.beta
    )
    return df["z_m"].to_numpy(float) + eps


def estimate_phantom_lift(
    dist: pd.DataFrame,
    phantom,
    *,
    nominal: pd.DataFrame | None = None,
    smooth_s: float = 0.2,
    baseline_s: float = 1.0,
) -> pd.DataFrame:
    """Estimates the phantom's z offset over time from a real ``_dist`` log.

    Method: the apparent surface under the probe (:func:`apparent_surface_z_m`,
    tip height + static Hunt-Crossley penetration for the measured force) is
    compared with the undisturbed surface at the same x: the apparent surface
    of the matching nominal log when given (which cancels the map's own
    errors and the rig's constant offsets), else the phantom map's surface.
    The difference is smoothed with a centred moving average of smooth_s,
    its median over the first baseline_s is removed (the phantom is assumed
    at rest at the start), and contact-loss gaps (no force, no information)
    are bridged linearly. Assumes the phantom moves rigidly and vertically
    and keeps its map (kappa) under the probe.

    Returns:
        DataFrame with t_s, phantom_lift_m, and measured (bool: from contact,
        False where bridged).
    """
    _require(dist, "t_s", "x_m", "y_m", "z_m", "force_sensor_z_N")
    s_dist = apparent_surface_z_m(dist, phantom)
    x = dist["x_m"].to_numpy(float)
    if nominal is not None:
        s_nom = apparent_surface_z_m(nominal, phantom)
        xn = nominal["x_m"].to_numpy(float)
        ok = np.isfinite(s_nom)
        order = np.argsort(xn[ok])
        ref = np.interp(x, xn[ok][order], s_nom[ok][order])
    else:
        ref = np.asarray(phantom.surface_z(x, dist["y_m"].to_numpy(float)), float)
    raw = s_dist - ref
    t = dist["t_s"].to_numpy(float)
    dt = float(np.median(np.diff(t)))
    n = max(1, int(round(smooth_s / dt)))
    measured = np.isfinite(raw)
    if measured.sum() < 2:
        raise VicDrakeError(
            "the disturbance log has no contact; cannot estimate a lift"
        )
    filled = np.interp(t, t[measured], raw[measured])
    kernel = np.ones(n) / n
    smooth = np.convolve(
        np.pad(filled, (n // 2, n - 1 - n // 2), mode="edge"), kernel, "valid"
    )
    base_sel = measured & (t <= t[0] + baseline_s)
    base = float(np.median(smooth[base_sel])) if base_sel.any() else 0.0
    return pd.DataFrame(
        {"t_s": t, "phantom_lift_m": smooth - base, "measured": measured}
    )


def lift_table(lift: pd.DataFrame, *, dt_s: float = 0.05) -> list[list[float]]:
    """Resamples an estimated lift to a [t_s, z_offset_m] table for the scenario."""
    t = lift["t_s"].to_numpy(float)
    grid = np.arange(t[0], t[-1] + 1e-9, dt_s)
    z = np.interp(grid, t, lift["phantom_lift_m"].to_numpy(float))
    z = np.clip(z, -0.1, 0.1)
    return [[float(a), float(b)] for a, b in zip(grid, z)]


__all__ = [
    "CANONICAL_COLUMNS",
    "CONTACT_THRESHOLD_N",
    "MIN_CONTACT_LOSS_S",
    "PenetrationStats",
    "RIB_KAPPA_THRESHOLD",
    "SETTLE_S",
    "apparent_surface_z_m",
    "compare_contact_loss",
    "compare_with_real",
    "contact_loss_intervals",
    "contact_mask",
    "estimate_force_loop_gain",
    "estimate_phantom_lift",
    "estimate_tissue_friction",
    "estimate_time_offset_s",
    "force_range_N",
    "force_rmse_N",
    "lead_force",
    "lift_table",
    "lifted_off",
    "liftoff_clearance_m",
    "peak_force_N",
    "penetration_stats",
    "pressing_force_N",
    "real_to_canonical",
    "resample",
    "scan_window",
    "shift_time",
    "tank_min_J",
]
