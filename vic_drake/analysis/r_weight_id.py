"""The stiffness QP weight R of a real variable-impedance log, read off its K_z.

R is not logged, but the stiffness QP replay is exact
(:func:`vic_drake.control.replay.replay_controller_log`): on a tick whose
K_z is strictly inside its bounds with no force or tank row active, K_z is
the unconstrained optimum of its axis and gives R in closed form
(:func:`r_weight_per_tick`). :func:`identify_r_weight` takes their median
and confirms it by replaying the QP.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd

from vic_drake.control.params import ControllerParams
from vic_drake.control.replay import REPLAY_COLUMNS
from vic_drake.control.stiffness_qp.problem import make_stiffness_qp_problem
from vic_drake.errors import VicDrakeError

#: A logged force matches a law when within this, N. The 31-column logs'
#: forces (references, bounds, the QP's K e + D e_dot) are the controller's
#: own computed values logged as float64: they match their law to rounding
#: (1e-12 N); 1 mN is far above that and far below any difference between
#: the laws that matters to a scan.
LAW_TOL_N = 1e-3
#: Fewest ticks with K_z strictly inside its bounds and no force or tank
#: row active, largest spread (median absolute deviation of log10 R) of the
#: per-tick values, and largest median |K_z| error of the confirming replay
#: relative to the K_z range (the replay is exact to rounding on the rig's
#: logs, so a visible error means R or the QP is not the log's).
MIN_R_TICKS = 50
MAX_R_SPREAD_LOG10 = 0.05
MAX_REPLAY_KZ_ERR_REL = 1e-3
#: Significant digits R is given with.
R_DIGITS = 6

#: Settings the 31-column logs hold every tick: setting name -> column.
LOGGED_SETTINGS = {
    "eps_max_m": "eps_max_m",
    "stiffness_z_min_N_per_m": "stiffness_z_min_N_per_m",
    "stiffness_z_max_N_per_m": "stiffness_z_max_N_per_m",
    "tank_min_J": "tank_min_J",
    "power_limit_W": "power_limit_W",
}


def logged_setting(df: pd.DataFrame, column: str) -> float:
    """The median of a column the controller logs as a setting."""
    return float(np.median(df[column].to_numpy(dtype=float)))


def logged_params(df: pd.DataFrame, r_weight: float) -> ControllerParams:
    """The real controller's parameters with R on every axis, the exact QP
    solver and the settings the log holds (K_z bounds, T_min, power limit),
    as the replay reads them."""
    p = ControllerParams()
    k_lo, k_hi = list(p.qp.stiffness_min_N_per_m), list(p.qp.stiffness_max_N_per_m)
    k_lo[2] = logged_setting(df, "stiffness_z_min_N_per_m")
    k_hi[2] = logged_setting(df, "stiffness_z_max_N_per_m")
    qp = replace(
        p.qp,
        r_weight=[r_weight] * 3,
        stiffness_min_N_per_m=k_lo,
        stiffness_max_N_per_m=k_hi,
        solver="exact",
    )
    tank = replace(
        p.tank,
        min_energy_J=logged_setting(df, "tank_min_J"),
        power_limit_W=-logged_setting(df, "power_limit_W"),
    )
    return replace(p, qp=qp, tank=tank)


def r_weight_per_tick(real: pd.DataFrame) -> np.ndarray:
    """The stiffness QP weight R each tick's logged K_z implies, where it can.

    On a tick whose K_z lies strictly inside its bounds with no force or
    tank row active (and a tank above T_min), K_z is the unconstrained
    optimum of its axis, ``K = (Q e (F_ref - D e_dot) + R K_min) / (Q e^2 +
    R)``, so ``R = Q e (F_ref - D e_dot - e K) / (K - K_min)``, with e, e_dot,
    D (from the previous tick's K) and F_ref as the replay takes them
    (:func:`vic_drake.control.replay.replay_controller_log`; the tank rows
    from :func:`vic_drake.control.stiffness_qp.make_stiffness_qp_problem`).

    Returns:
        R of the qualifying ticks (may be empty).
    """
    params = logged_params(real, 1.0)
    qp, tank = params.qp, params.tank
    data = real[list(REPLAY_COLUMNS)].to_numpy(dtype=float)
    k_lo, k_hi = qp.stiffness_min_N_per_m[2], qp.stiffness_max_N_per_m[2]
    f_hi = qp.force_max_N[2]
    q = qp.q_weight[2]
    edge = 1e-6 * max(k_hi - k_lo, 1.0)
    out = []
    for prev, row in zip(data[:-1].tolist(), data[1:].tolist()):
        t, x, y, z, xd, yd, zd, vx, vy, vz, f_ref, f_min, _, kx, ky, kz = row
        energy, dt = prev[12], t - prev[0]
        if not (k_lo + edge < kz < k_hi - edge) or energy < tank.min_energy_J:
            continue
        d = tuple(2.0 * qp.damping_ratio * math.sqrt(max(k, 0.0)) for k in prev[13:16])
        e, e_dot = (xd - x, yd - y, zd - z), (-vx, -vy, -vz)
        force = e[2] * kz + d[2] * e_dot[2]
        if not (f_min + LAW_TOL_N < force < f_hi - LAW_TOL_N) or e[2] == 0.0:
            continue
        p = make_stiffness_qp_problem(
            e, e_dot, d, (0.0, 0.0, f_ref), (*qp.force_min_N[:2], f_min),
            energy, dt, qp, tank,
        )  # fmt: skip
        ak = p.tank_a[0] * kx + p.tank_a[1] * ky + p.tank_a[2] * kz
        lb = max(p.tank_lb_energy, p.tank_lb_power)
        if not ak > lb + 1e-6 * (1.0 + abs(lb)):
            continue
        out.append(q * e[2] * (f_ref - d[2] * e_dot[2] - e[2] * kz) / (kz - k_lo))
    r = np.asarray(out, dtype=float)
    return r[np.isfinite(r) & (r > 0.0)]


def identify_r_weight(real: pd.DataFrame) -> dict:
    """The stiffness QP weight R a 31-column log ran with, confirmed by replay.

    R is the median (in log scale) of :func:`r_weight_per_tick`, to
    :data:`R_DIGITS` significant digits; the QP is
    then replayed with it through the project's replay
    (:func:`vic_drake.control.replay.replay_controller_log`, exact solver),
    whose K_z errors are reported.

    Returns:
        dict with ``r_weight``, ``r_ticks``, ``r_spread_log10`` (median
        absolute deviation of log10 R), ``replay_kz_err_median``,
        ``replay_kz_err_max`` (N/m).

    Raises:
        VicDrakeError: too few usable ticks, per-tick values that disagree,
            or a replay that does not reproduce the logged K_z.
    """
    from vic_drake.control.replay import replay_controller_log

    ask = "pass --R R"
    r = r_weight_per_tick(real)
    if r.size < MIN_R_TICKS:
        raise VicDrakeError(
            f"cannot read R off this log: only {r.size} ticks have K_z strictly inside "
            f"its bounds with no force or tank row active ({MIN_R_TICKS} needed); {ask}"
        )
    logs = np.log10(r)
    mid = float(np.median(logs))
    spread = float(np.median(np.abs(logs - mid)))
    if spread > MAX_R_SPREAD_LOG10:
        raise VicDrakeError(
            f"cannot read R off this log: the {r.size} usable ticks give R from "
            f"{10 ** np.percentile(logs, 10):.3g} to {10 ** np.percentile(logs, 90):.3g} "
            f"(10th-90th percentile; spread {spread:.3g} decades, at most "
            f"{MAX_R_SPREAD_LOG10} allowed); {ask}"
        )
    # The median's last digits are rounding noise; the replay below checks
    # the rounded value.
    r_weight = float(f"{10**mid:.{R_DIGITS}g}")
    replay = replay_controller_log(real, logged_params(real, r_weight))
    err = replay.kz_abs_err
    k_range = (
        replay.from_log["stiffness_z_max_N_per_m"]
        - replay.from_log["stiffness_z_min_N_per_m"]
    )
    out = {
        "r_weight": r_weight,
        "r_ticks": int(r.size),
        "r_spread_log10": spread,
        "replay_kz_err_median": float(np.median(err)),
        "replay_kz_err_max": float(np.max(err)),
    }
    if out["replay_kz_err_median"] > MAX_REPLAY_KZ_ERR_REL * max(k_range, 1.0):
        raise VicDrakeError(
            f"R = {r_weight:.3g} read off the log does not reproduce its K_z: the QP "
            f"replay misses it by {out['replay_kz_err_median']:.3g} N/m (median); {ask}"
        )
    return out


__all__ = [
    "LAW_TOL_N",
    "LOGGED_SETTINGS",
    "identify_r_weight",
    "logged_params",
    "logged_setting",
    "r_weight_per_tick",
]
