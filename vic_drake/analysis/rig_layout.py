"""A simulated scan in the real rig's log layouts: the inverse of real_to_canonical.

The real rig logged one row per controller tick: the 31-column
``/adaptive_stiffness_data`` rows of the variable-impedance controller and
the 9-column ``/data_control`` rows of the CS/CF baselines (the layouts of
:mod:`vic_drake.realdata`). :func:`controller_log_rows` and
:func:`scan_log_rows` build those rows from a simulated scan: its canonical
frame (:data:`vic_drake.analysis.columns.CANONICAL_COLUMNS`) and the signals
only a rig log holds (:data:`RIG_SIGNALS`, logged from the scan diagram).

Tick alignment. A rig row holds one tick as the real controller wrote it:
what the tick read (pose, velocity, sensor force, target) with the K that
tick chose and T after its update. The controller's systems store their
tick in discrete state, which a Drake logger sampling at t_n sees only
after their update at t_{n-1}: canonical row n+1 holds tick n's K, T,
F_ref, F_min, and the rig signals of row n+1 (the reference system's tick
record) hold what tick n read and its map sample. The target is a function
of time, read by tick n at t_n: canonical row n. So rig row n takes
t_n and the target from canonical row n, everything else from row n+1; a
scan of N logged samples gives N-1 rows. With that,
:func:`vic_drake.control.replay.replay_controller_log` solves each row's
QP from the row's own inputs and finds the row's K.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import require_columns
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import CONTROLLER_COLUMNS, SCAN_COLUMNS
from vic_drake.realdata_write import LAYOUT_TOPICS

#: Signals of a rig log that the canonical frame does not hold, as the scan
#: diagram logs them (same sampling as the canonical frame), all from the
#: controller's reference system's state (its last tick): the position,
#: velocity and F/T force (in W, sensor convention) the tick read, the map's
#: kappa and lambda there, the map-based penetration (map surface - z) and
#: the surface-velocity estimate.
RIG_SIGNALS = (
    "controller_x_m",
    "controller_y_m",
    "controller_z_m",
    "controller_vx_m_per_s",
    "controller_vy_m_per_s",
    "controller_vz_m_per_s",
    "controller_force_x_N",
    "controller_force_y_N",
    "controller_force_z_N",
    "kappa_N_per_m_beta",
    "lambda_N_s_per_m_beta1",
    "map_penetration_m",
    "surface_velocity_m_per_s",
)


def _check(df: pd.DataFrame, rig: pd.DataFrame, rows_needed: int) -> int:
    require_columns(
        df,
        "t_s",
        "x_d_m",
        "y_d_m",
        "z_d_m",
        "force_ref_z_N",
        "force_min_z_N",
        "tank_energy_J",
        *(f"stiffness_{a}_N_per_m" for a in "xyz"),
    )
    missing = [c for c in RIG_SIGNALS if c not in rig.columns]
    if missing:
        raise VicDrakeError(
            f"rig signals lack columns {missing}; expected "
            "vic_drake.analysis.rig_layout.RIG_SIGNALS (logged by run_scan)"
        )
    if len(rig) != len(df):
        raise VicDrakeError(
            f"rig signals have {len(rig)} rows, the scan frame {len(df)}: they must "
            "be sampled together"
        )
    if len(df) < rows_needed:
        raise VicDrakeError(
            f"a rig log needs at least {rows_needed} logged samples; the scan has "
            f"{len(df)}"
        )
    return len(df)


def controller_log_rows(
    df: pd.DataFrame,
    rig: pd.DataFrame,
    *,
    stiffness_z_min_N_per_m: float,
    stiffness_z_max_N_per_m: float,
    eps_max_m: float,
    tank_min_J: float,
    power_limit_W: float,
    damping_ratio: float,
    beta: float,
) -> pd.DataFrame:
    """The 31-column controller log of a simulated scan (module doc: alignment).

    Args:
        df: the canonical scan frame, sampled once per controller tick.
        rig: the :data:`RIG_SIGNALS` of the same samples.
        stiffness_z_min_N_per_m, stiffness_z_max_N_per_m: K_z bounds (cols 18, 17).
        eps_max_m: eps_max (col 24).
        tank_min_J: T_min (col 25).
        power_limit_W: the tank's power limit as the rig logged it, > 0
            (col 26; TankParams.power_limit_W is its negative).
        damping_ratio: zeta of D = 2 zeta sqrt(K) (col 7).
        beta: the Hunt-Crossley exponent (col 23).

    Returns:
        DataFrame of :data:`vic_drake.realdata.CONTROLLER_COLUMNS`, one row per
        tick (len(df) - 1 rows). As on the rig: col 7 is K_z e_z +
        2 zeta sqrt(K_z) e_dot_z with this tick's K_z; col 13 is T after this
        tick minus T after the previous one; col 23 is (kappa - lambda (v_z -
        surface velocity)) penetration^beta, NaN out of the tissue
        (penetration < 0).
    """
    n = _check(df, rig, 2) - 1
    now = slice(0, n)  # Tick n's time and target.
    after = slice(1, n + 1)  # What tick n read and computed.

    def col(frame, name, rows=after):
        return frame[name].to_numpy(dtype=float)[rows]

    p = [col(rig, f"controller_{a}_m") for a in "xyz"]
    v = [col(rig, f"controller_v{a}_m_per_s") for a in "xyz"]
    f = [col(rig, f"controller_force_{a}_N") for a in "xyz"]
    p_d = [col(df, f"{a}_d_m", now) for a in "xyz"]
    k = [col(df, f"stiffness_{a}_N_per_m") for a in "xyz"]
    energy_all = df["tank_energy_J"].to_numpy(dtype=float)
    energy = energy_all[after]
    pen = col(rig, "map_penetration_m")
    kappa = col(rig, "kappa_N_per_m_beta")
    lam = col(rig, "lambda_N_s_per_m_beta1")
    surf_v = col(rig, "surface_velocity_m_per_s")
    e_z, e_dot_z = p_d[2] - p[2], -v[2]
    with np.errstate(invalid="ignore"):
        hc = np.where(
            pen >= 0.0,
            (kappa - lam * (v[2] - surf_v)) * np.abs(pen) ** beta,
            np.nan,
        )
    # The logged x, y forces are the external force in the sensor frame S
    # (x_S = x_W, y_S = -y_W): the inverse of real_to_canonical's x flip.
    values = {
        "t_s": col(df, "t_s", now),
        "x_m": p[0],
        "y_m": p[1],
        "z_m": p[2],
        "x_d_m": p_d[0],
        "y_d_m": p_d[1],
        "z_d_m": p_d[2],
        "force_model_z_N": k[2] * e_z
        + 2.0 * damping_ratio * np.sqrt(np.maximum(k[2], 0.0)) * e_dot_z,
        "sensor_force_x_N": -f[0],
        "sensor_force_y_N": f[1],
        "sensor_force_z_N": f[2],
        "force_ref_z_N": col(df, "force_ref_z_N"),
        "tank_energy_J": energy,
        "tank_delta_J": energy - energy_all[now],
        "stiffness_x_N_per_m": k[0],
        "stiffness_y_N_per_m": k[1],
        "stiffness_z_N_per_m": k[2],
        "stiffness_z_max_N_per_m": np.full(n, float(stiffness_z_max_N_per_m)),
        "stiffness_z_min_N_per_m": np.full(n, float(stiffness_z_min_N_per_m)),
        "penetration_m": pen,
        "kappa_N_per_m_beta": kappa,
        "lambda_N_s_per_m_beta1": lam,
        "force_min_z_N": col(df, "force_min_z_N"),
        "force_hc_N": hc,
        "eps_max_m": np.full(n, float(eps_max_m)),
        "tank_min_J": np.full(n, float(tank_min_J)),
        "power_limit_W": np.full(n, float(power_limit_W)),
        "vx_m_per_s": v[0],
        "vy_m_per_s": v[1],
        "vz_m_per_s": v[2],
        "surface_velocity_m_per_s": surf_v,
    }
    out = pd.DataFrame(values)[list(CONTROLLER_COLUMNS)]
    out.attrs.update(layout="controller", topic=LAYOUT_TOPICS["controller"])
    return out


def scan_log_rows(
    df: pd.DataFrame, rig: pd.DataFrame, *, sensor_lag_samples: int = 0
) -> pd.DataFrame:
    """The 9-column CS/CF scan log of a simulated scan.

    Row n: tick n's time, target, and the pose and velocity the tick read,
    with the pressing force the controller read ``sensor_lag_samples``
    ticks later (the rig paired each pose with the force 28 samples later
    to undo its sensor's lag; the simulated sensor lags by
    ``StationParams.sensor_lag_samples``, 0 by default).
    ``surface_z_start_m`` is the map surface under the probe at the first
    tick (its z plus that tick's map penetration); ``palpation_no`` is 0 as
    on every real scan log.

    Returns:
        DataFrame of :data:`vic_drake.realdata.SCAN_COLUMNS`, len(df) - 1 -
        sensor_lag_samples rows.
    """
    lag = int(sensor_lag_samples)
    if lag != sensor_lag_samples or lag < 0:
        raise VicDrakeError(
            f"sensor_lag_samples must be an integer >= 0; got {sensor_lag_samples!r}"
        )
    n = _check(df, rig, lag + 2) - 1 - lag
    now, after = slice(0, n), slice(1, n + 1)

    def col(frame, name, rows=after):
        return frame[name].to_numpy(dtype=float)[rows]

    z = col(rig, "controller_z_m")
    surface_start = z[0] + float(rig["map_penetration_m"].iloc[1])
    values = {
        "t_s": col(df, "t_s", now),
        "surface_z_start_m": np.full(n, surface_start),
        "z_m": z,
        "z_target_m": col(df, "z_d_m", now),
        "vz_m_per_s": col(rig, "controller_vz_m_per_s"),
        "force_pressing_z_N": -col(
            rig, "controller_force_z_N", slice(1 + lag, n + 1 + lag)
        ),
        "palpation_no": np.zeros(n),
        "x_m": col(rig, "controller_x_m"),
        "y_m": col(rig, "controller_y_m"),
    }
    out = pd.DataFrame(values)[list(SCAN_COLUMNS)]
    out.attrs.update(layout="scan", topic=LAYOUT_TOPICS["scan"])
    return out


__all__ = ["RIG_SIGNALS", "controller_log_rows", "scan_log_rows"]
