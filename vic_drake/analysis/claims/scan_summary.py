"""One scan log reduced to the numbers the scan claims (C4-C7) need.

The controller settings the claims compare against (:class:`ScanLimits`)
come from the controller's own parameters, whose defaults are the real
controller's settings; they are not written down a second time here.
"""

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from vic_drake.analysis.claims.thresholds import (
    C7_K_MIN_TOL_N_PER_M,
    C7_LOSS_SETTLE_S,
)
from vic_drake.analysis.columns import check_frame
from vic_drake.analysis.contact import (
    CONTACT_THRESHOLD_N,
    SCAN_HEIGHT_TOL_M,
    SETTLE_S,
    contact_loss_intervals,
    pressing_force_N,
    scan_window,
)
from vic_drake.analysis.scan_metrics import force_rmse_N, tank_min_J
from vic_drake.control.params import ControllerParams
from vic_drake.control.references import has_tank as controller_has_tank
from vic_drake.errors import VicDrakeError


def _default(getter):
    return field(default_factory=lambda: getter(ControllerParams()))


@dataclass(frozen=True)
class ScanLimits:
    """Controller settings the scan claims compare against.

    Defaults: those of :class:`vic_drake.control.params.ControllerParams`
    (the real controller's settings).

    Attributes:
        k_min_z_N_per_m: minimum z stiffness K_min.
        tank_min_J: T_min.
        power_max_W: the power valve's limit P_max (> 0).
        eps_d_m: VS-VF's desired penetration.
        has_tank: the controller has an energy tank (VS-CF, VS-VF); without
            one (CS, CF) the tank metrics are NaN.
        targets_penetration: the controller's reference aims at eps_d
            (VS-VF); for the others the penetration error against eps_d
            means nothing and is not given. None: the controller is not
            known (a rig log scored on the defaults): given.
    """

    k_min_z_N_per_m: float = _default(lambda p: p.qp.stiffness_min_N_per_m[2])
    tank_min_J: float = _default(lambda p: p.tank.min_energy_J)
    power_max_W: float = _default(lambda p: -p.tank.power_limit_W)
    eps_d_m: float = _default(lambda p: p.reference.eps_d_m)
    has_tank: bool = True
    targets_penetration: bool | None = None

    @classmethod
    def from_controller(cls, params: ControllerParams) -> "ScanLimits":
        """The limits of the controller that ran the scan."""
        return cls(
            k_min_z_N_per_m=float(params.qp.stiffness_min_N_per_m[2]),
            tank_min_J=float(params.tank.min_energy_J),
            power_max_W=float(-params.tank.power_limit_W),
            eps_d_m=float(params.reference.eps_d_m),
            has_tank=controller_has_tank(params.reference),
            targets_penetration=params.reference.controller == "vs-vf",
        )


REQUIRED_SCAN_COLUMNS = ("t_s", "z_d_m", "force_sensor_z_N")


def scan_metrics(
    df: pd.DataFrame,
    *,
    limits: ScanLimits | None = None,
    settle_s: float = SETTLE_S,
    end_s: float = 0.5,
) -> dict:
    """Reduces one scan log to the numbers the claims C4-C7 need.

    Args:
        df: canonical scan DataFrame; optional columns are used where present.
        limits: controller settings (K_min, T_min, P_max, eps_d); default:
            the log's own (``df.attrs["scan_limits"]``, which ``run_scan``
            sets), else ScanLimits() (the real controller's).
        settle_s: seconds after first contact excluded from the scan window.
        end_s: length of the final segment checked for lift-off, s.

    Returns:
        dict with force_rmse_N (:func:`~vic_drake.analysis.scan_metrics.force_rmse_N`
        over the scan window; only where there is a force reference), force_range_N
        (98th - 2nd percentile of the pressing force in the window),
        peak_force_N (whole run), lifted_off (mean pressing force of the
        last end_s below the contact threshold), lift_commanded (the target
        ends above its scan height; only with a scan window), and where the columns
        exist: penetration / force-cap metrics (C6), contact-loss, stiffness
        and tank metrics (C7; the tank's NaN for a controller without one,
        ``limits.has_tank`` False).
    """
    check_frame(df)
    if limits is None:
        # A simulated log carries its controller's limits (run_scan sets
        # them); a rig log is scored against the real controller's.
        stored = df.attrs.get("scan_limits")
        limits = ScanLimits(**stored) if stored else ScanLimits()
    if not isinstance(limits, ScanLimits):
        raise VicDrakeError(
            "scan_metrics: limits must be a ScanLimits "
            "(ScanLimits.from_controller(scenario.controller)); got a "
            f"{type(limits).__name__}"
        )
    missing = [c for c in REQUIRED_SCAN_COLUMNS if c not in df.columns]
    if missing:
        raise VicDrakeError(
            f"scan_metrics: DataFrame lacks columns {missing}; "
            f"needs {list(REQUIRED_SCAN_COLUMNS)}"
        )
    if len(df) < 10:
        raise VicDrakeError(f"scan_metrics: the log has {len(df)} rows; needs >= 10")
    t = df["t_s"].to_numpy(float)
    f = pressing_force_N(df)
    w = scan_window(df, settle_s=settle_s)
    out: dict[str, Any] = {"duration_s": float(t[-1] - t[0]), "n_window": int(w.sum())}
    out["peak_force_N"] = float(np.max(f))
    end = t >= t[-1] - end_s
    out["final_force_N"] = float(np.mean(f[end]))
    out["lifted_off"] = bool(out["final_force_N"] < CONTACT_THRESHOLD_N)
    if w.any():
        # Whether the run asked for a lift at its end (the target leaves its
        # scan height): the rig's CS and CF logs end at the scan height, so
        # their staying in contact says nothing about lifting off.
        z_d = df["z_d_m"].to_numpy(float)
        out["lift_commanded"] = bool(z_d[-1] > np.median(z_d[w]) + SCAN_HEIGHT_TOL_M)
    if w.sum() >= 10:
        fw = f[w]
        lo, hi = np.percentile(fw, [2, 98])
        out["force_range_N"] = float(hi - lo)
        out["force_mean_N"] = float(np.mean(fw))
        if "force_ref_z_N" in df.columns:
            # Only a controller with a force reference (CF, VS-CF, VS-VF) has a
            # tracking error (force_rmse_N's rule).
            rmse = force_rmse_N(df, mask=w)
            if np.isfinite(rmse):
                out["force_rmse_N"] = rmse
    out.update(_force_cap_metrics(df, w, f, limits))
    if w.any():
        out.update(_contact_loss_metrics(df, w, limits))
    if "tank_energy_J" in df.columns:
        out["tank_min_J"] = tank_min_J(df, has_tank=limits.has_tank)
    if "tank_power_W" in df.columns:
        out["tank_power_min_W"] = (
            float(df["tank_power_W"].min()) if limits.has_tank else float("nan")
        )
    if "stiffness_z_N_per_m" in df.columns:
        out["stiffness_z_max_N_per_m"] = float(df["stiffness_z_N_per_m"].max())
    return out


def _force_cap_metrics(df, w, f, limits: ScanLimits) -> dict:
    """C6: penetration off the ribs, force over the ribs (where the cap binds).

    "Over the ribs" is where the force reference F_body(eps_d) exceeds |F_min|
    (the cap binds); "off the ribs" where it is below 0.9 |F_min|.
    """
    cols = {"force_ref_z_N", "force_min_z_N", "penetration_m"}
    if not (cols <= set(df.columns) and w.sum()):
        return {}
    ref = -df["force_ref_z_N"].to_numpy(float)
    cap = -df["force_min_z_N"].to_numpy(float)
    pen = df["penetration_m"].to_numpy(float)
    off = w & (ref < 0.9 * cap)
    on = w & (ref > cap)
    out = {"n_off_ribs": int(off.sum()), "n_on_ribs": int(on.sum())}
    if off.sum() >= 10:
        out["penetration_off_ribs_median_m"] = float(np.median(pen[off]))
        if limits.targets_penetration is not False:  # Only VS-VF aims at eps_d.
            err = np.abs(pen[off] - limits.eps_d_m)
            out["penetration_error_off_ribs_median_m"] = float(np.median(err))
    if on.sum() >= 10:
        out["force_on_ribs_p99_N"] = float(np.percentile(f[on], 99))
        out["force_cap_N"] = float(np.median(cap[on]))
    return out


def _contact_loss_metrics(df, w, limits: ScanLimits) -> dict:
    """C7: contact losses in the scan window and the stiffness during them."""
    losses = contact_loss_intervals(df, window=w)
    out = {
        "n_contact_losses": len(losses),
        "contact_loss_s": float(sum(b - a for a, b in losses)),
    }
    if losses and "stiffness_z_N_per_m" in df.columns:
        t = df["t_s"].to_numpy(float)
        k = df["stiffness_z_N_per_m"].to_numpy(float)
        sel = np.zeros(len(t), bool)
        for a, b in losses:
            sel |= (t >= a + C7_LOSS_SETTLE_S) & (t < b)
        if sel.any():
            at_min = k[sel] <= limits.k_min_z_N_per_m + C7_K_MIN_TOL_N_PER_M
            out["fraction_at_k_min_during_loss"] = float(at_min.mean())
            out["k_max_during_loss_N_per_m"] = float(k[sel].max())
    return out


__all__ = ["REQUIRED_SCAN_COLUMNS", "ScanLimits", "scan_metrics"]
