"""Force, tank and penetration metrics of one scan (canonical table).

The windows, the contact rule and the contact losses these use are defined
once in :mod:`vic_drake.analysis.contact`.
"""

from dataclasses import dataclass

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import require_columns
from vic_drake.analysis.contact import contact_mask, pressing_force_N, scan_window
from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTACT_THRESHOLD_N

#: kappa above which a point counts as "over a rib", N/m^beta. The measured
#: map's soft tissue lies at 2,000-5,500 and its rib lines reach 9,000-10,236;
#: 7,000 sits in the gap between the two populations of the histogram.
RIB_KAPPA_THRESHOLD = 7000.0


def _window_or(df: pd.DataFrame, mask) -> np.ndarray:
    """The mask given (one bool per row of ``df``), else the scan window."""
    if mask is None:
        return scan_window(df)
    mask = np.asarray(mask, bool)
    if mask.shape != (len(df),):
        raise VicDrakeError(
            f"mask must hold one bool per row of the log ({len(df)}); got shape "
            f"{mask.shape}"
        )
    return mask


def force_rmse_N(df: pd.DataFrame, *, mask=None) -> float:
    """RMS of (measured - reference) z force over the mask (default: scan window), N.

    The reference is ``force_ref_z_N``; samples where it is NaN are skipped,
    and so are the ticks the controller skipped on a non-finite reading
    (``qp_fault`` = 1, where logged): their F_ref = 0 is no reference. NaN
    where there is no force reference: a CS log (``df.attrs["controller"]``,
    which ``run_scan`` sets), or a reference that is zero over the whole mask
    (CS logs a 0, which would score the pressing force).

    The reference is the one logged, before the QP's cap F_min: where VS-VF's
    reference asks for more than the cap (over the ribs), the force the cap
    holds back counts as error. Compare VS-VF with CF on it with that in
    mind, or pass a ``mask`` that leaves those samples out
    (``force_ref_z_N >= force_min_z_N``).
    """
    require_columns(df, "force_sensor_z_N", "force_ref_z_N")
    if df.attrs.get("controller") == "cs":
        return float("nan")
    mask = _window_or(df, mask)
    ref = df["force_ref_z_N"].to_numpy(float)
    if "qp_fault" in df:
        mask = mask & ~(df["qp_fault"].to_numpy(float) > 0.5)
    if not np.any(np.abs(ref[mask]) > 0):
        return float("nan")
    err = df["force_sensor_z_N"].to_numpy(float) - ref
    err = err[mask & np.isfinite(err)]
    return float(np.sqrt(np.mean(err**2))) if err.size else float("nan")


def force_range_N(df: pd.DataFrame, *, mask=None) -> tuple[float, float]:
    """(min, max) pressing force over the mask (default: scan window), N."""
    mask = _window_or(df, mask)
    f = pressing_force_N(df)[mask]
    return (float(f.min()), float(f.max())) if f.size else (float("nan"), float("nan"))


def peak_force_N(df: pd.DataFrame) -> float:
    """Largest pressing force of the whole run, N."""
    return float(np.nanmax(pressing_force_N(df)))


def tank_min_J(df: pd.DataFrame, *, has_tank: bool | None = None) -> float:
    """Lowest tank energy of the run, J.

    NaN if the tank is not logged, or if the controller has none
    (``has_tank`` False: CS and CF, :func:`vic_drake.control.references.has_tank`;
    their log holds the tank's initial energy throughout). ``has_tank``
    None: from the log's ``attrs["controller"]`` (``run_scan`` sets it),
    True for a log without it.
    """
    if has_tank is None:
        has_tank = df.attrs.get("controller") not in ("cs", "cf")
    if not has_tank:
        return float("nan")
    require_columns(df, "tank_energy_J")
    e = df["tank_energy_J"].to_numpy(float)
    return float(np.nanmin(e)) if np.isfinite(e).any() else float("nan")


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
    require_columns(df, "x_m", "y_m", "penetration_m")
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
    require_columns(df, "t_s", "penetration_m")
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
