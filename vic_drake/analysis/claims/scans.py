"""Claims C4-C7 of the online phase: the scans of the four controllers,
nominal (Fig. 6) and under the disturbance (Fig. 7).
"""

from collections.abc import Mapping
from typing import Any

import numpy as np

from vic_drake.analysis.claims.claim import Claim, clean, two_sided
from vic_drake.analysis.claims.scan_summary import ScanLimits
from vic_drake.analysis.claims.thresholds import (
    C4_MAX_RMSE_RATIO,
    C5_MIN_RANGE_RATIO,
    C6_FORCE_CAP_TOL,
    C6_MAX_PEN_ERROR_M,
    C7_K_MIN_TOL_N_PER_M,
    C7_LOSS_SETTLE_S,
    C7_MIN_FRACTION_AT_K_MIN,
    C7_POWER_TOL,
    C7_TANK_TOL_J,
)
from vic_drake.control.params import ReferenceParams
from vic_drake.paper import CONTACT_THRESHOLD_N

#: The paper's reference settings (the real controller's: the defaults).
_PAPER_REFERENCE = ReferenceParams(controller="vs-vf")


def _need(d: Mapping | None, *keys) -> bool:
    return d is not None and all(d.get(k) is not None for k in keys)


def _why_missing(runs: Mapping[str, Mapping | None], keys: Mapping[str, tuple]) -> str:
    """Why a side cannot be evaluated although its stage ran: which run is
    absent, or which metric a run lacks (with its scan-window size)."""
    parts = []
    for name, need in keys.items():
        m = runs.get(name)
        if m is None:
            parts.append(f"no {name.upper()} scan")
            continue
        lacking = [k for k in need if m.get(k) is None]
        if lacking:
            parts.append(
                f"the {name.upper()} scan ran ({m.get('n_window', 0)} samples in its "
                f"scan window) but gives no {', '.join(lacking)}"
            )
    return "; ".join(parts)


def _c4_side(vscf: Mapping | None, cf: Mapping | None):
    if not (
        _need(vscf, "force_rmse_N", "lifted_off")
        and _need(cf, "force_rmse_N", "lifted_off")
    ):
        return None, None
    ratio = (
        vscf["force_rmse_N"] / cf["force_rmse_N"] if cf["force_rmse_N"] > 0 else np.inf
    )
    # A run whose target never left its scan height (the rig's CF logs) says
    # nothing about lifting off: that part is not tested on it (None).
    vs_asked = vscf.get("lift_commanded", True)
    cf_asked = cf.get("lift_commanded", True)
    value = {
        "force_rmse_vs_cf_N": vscf["force_rmse_N"],
        "force_rmse_cf_N": cf["force_rmse_N"],
        "rmse_ratio": ratio,
        "vs_cf_lifted_off": vscf["lifted_off"] if vs_asked else None,
        "cf_lifted_off": cf["lifted_off"] if cf_asked else None,
    }
    lifts = (not vs_asked or vscf["lifted_off"]) and (
        not cf_asked or not cf["lifted_off"]
    )
    return value, bool(ratio <= C4_MAX_RMSE_RATIO and lifts)


def claim_c4(
    sim: Mapping[str, Mapping] | None,
    real: Mapping[str, Mapping] | None,
    *,
    reason_sim: str | None = None,
    reason_real: str | None = None,
) -> Claim:
    """C4: VS-CF's force RMSE <= 1.2 x CF's; VS-CF lifts off at the end, CF not.

    Args:
        sim, real: {"vs-cf": scan_metrics(...), "cf": scan_metrics(...)}.
    """
    need = {k: ("force_rmse_N", "lifted_off") for k in ("vs-cf", "cf")}
    sv, sp = _c4_side(*(sim.get(k) for k in ("vs-cf", "cf"))) if sim else (None, None)
    rv, rp = _c4_side(*(real.get(k) for k in ("vs-cf", "cf"))) if real else (None, None)
    if sim and sv is None:
        reason_sim = _why_missing(sim, need)
    if real and rv is None:
        reason_real = _why_missing(real, need)
    detail = (
        f"RMSE of pressing force vs reference over the scan window; pass: ratio <= "
        f"{C4_MAX_RMSE_RATIO}, VS-CF final force < {CONTACT_THRESHOLD_N} N, CF's not "
        "(each where its run commanded a lift at the end; a lifted_off of None: "
        "none was, as in the rig's CF logs, so that part is untested there)"
    )
    return two_sided(
        "C4",
        "VS-CF tracks the reference force as well as force control; only "
        "VS-CF can lift off the surface",
        (sv, sp),
        (rv, rp),
        detail,
        reason_sim,
        reason_real,
    )


def _c5_side(cs: Mapping | None, vscf: Mapping | None):
    if not (_need(cs, "force_range_N") and _need(vscf, "force_range_N")):
        return None, None
    ratio = (
        cs["force_range_N"] / vscf["force_range_N"]
        if vscf["force_range_N"] > 0
        else np.inf
    )
    value = {
        "force_range_cs_N": cs["force_range_N"],
        "force_range_vs_cf_N": vscf["force_range_N"],
        "range_ratio": ratio,
    }
    return value, bool(ratio >= C5_MIN_RANGE_RATIO)


def claim_c5(
    sim: Mapping[str, Mapping] | None,
    real: Mapping[str, Mapping] | None,
    *,
    reason_sim: str | None = None,
    reason_real: str | None = None,
) -> Claim:
    """C5: CS's force range over the scan >= 2 x VS-CF's.

    Args:
        sim, real: {"cs": scan_metrics(...), "vs-cf": scan_metrics(...)}.
    """
    need = {k: ("force_range_N",) for k in ("cs", "vs-cf")}
    sv, sp = _c5_side(*(sim.get(k) for k in ("cs", "vs-cf"))) if sim else (None, None)
    rv, rp = _c5_side(*(real.get(k) for k in ("cs", "vs-cf"))) if real else (None, None)
    if sim and sv is None:
        reason_sim = _why_missing(sim, need)
    if real and rv is None:
        reason_real = _why_missing(real, need)
    detail = (
        "force range = 98th - 2nd percentile of the pressing force over the scan "
        f"window; pass: ratio >= {C5_MIN_RANGE_RATIO}"
    )
    return two_sided(
        "C5",
        "CS force strongly depends on the body's shape",
        (sv, sp),
        (rv, rp),
        detail,
        reason_sim,
        reason_real,
    )


def _c6_side(vsvf: Mapping | None):
    """(value, verdict, why): each half of C6 judged on its own samples.

    Off the ribs: the median penetration error; over the ribs: the p99 force
    against the cap. A half that fails makes the side fail; a half with too
    few samples leaves the side not evaluated, with what happened in the scan.
    """
    if vsvf is None:
        return None, None, None
    if vsvf.get("n_off_ribs") is None:
        return (
            None,
            None,
            "the VS-VF log has no force reference, F_min or penetration columns",
        )
    value = {
        "penetration_off_ribs_median_m": vsvf.get("penetration_off_ribs_median_m"),
        "penetration_error_off_ribs_median_m": vsvf.get(
            "penetration_error_off_ribs_median_m"
        ),
        "force_on_ribs_p99_N": vsvf.get("force_on_ribs_p99_N"),
        "force_cap_N": vsvf.get("force_cap_N"),
        "n_on_ribs": vsvf.get("n_on_ribs"),
        "n_off_ribs": vsvf.get("n_off_ribs"),
    }
    halves, why = [], []
    err = value["penetration_error_off_ribs_median_m"]
    if err is None:
        why.append(
            f"the VS-VF scan has only {value['n_off_ribs']} samples off the ribs "
            "(force reference below 0.9 |F_min|) in its scan window; needs 10"
        )
    else:
        halves.append(err <= C6_MAX_PEN_ERROR_M)
    p99, cap = value["force_on_ribs_p99_N"], value["force_cap_N"]
    if p99 is None or cap is None:
        why.append(
            f"over the scan the VS-VF force reference F_body(eps_d) exceeded the cap "
            f"|F_min| on only {value['n_on_ribs']} samples (needs 10): the probe "
            "never pressed on a rib hard enough for the cap to bind, so the cap was "
            "not tested"
            + (
                ""
                if err is None
                else f" (off the ribs: median |eps - eps_d| = {err * 1e3:.2f} mm)"
            )
        )
    else:
        halves.append(p99 <= (1 + C6_FORCE_CAP_TOL) * cap)
    if not all(halves):
        return value, False, None
    if why:
        return value, None, "; ".join(why)
    return value, True, None


def claim_c6(
    sim: Mapping | None,
    real: Mapping | None,
    *,
    eps_d_m: float | None = None,
    reason_sim: str | None = None,
    reason_real: str | None = None,
) -> Claim:
    """C6: VS-VF: median |eps - eps_d| off ribs <= 3 mm; force over ribs capped.

    Args:
        sim, real: scan_metrics(...) of the VS-VF scan (computed with
            limits.eps_d_m = eps_d_m).

    "Over the ribs" is where the force reference F_body(eps_d) exceeds
    |F_min| (the cap binds); "off the ribs" where it is below 0.9 |F_min|.
    """
    eps_d_m = _PAPER_REFERENCE.eps_d_m if eps_d_m is None else eps_d_m
    sv, sp, why_sim = _c6_side(sim)
    rv, rp, why_real = _c6_side(real)
    reason_sim = why_sim or reason_sim
    reason_real = why_real or reason_real
    detail = (
        f"eps_d = {eps_d_m * 1e3:g} mm; pass: median |eps - eps_d| off ribs <= "
        f"{C6_MAX_PEN_ERROR_M * 1e3:g} mm and p99 force on ribs <= "
        f"{1 + C6_FORCE_CAP_TOL:g} x |F_min|"
    )
    return two_sided(
        "C6",
        {
            "eps_d_m": _PAPER_REFERENCE.eps_d_m,
            "F_min_N": _PAPER_REFERENCE.force_min_z_N,
            "text": "constant penetration tracked; the minimum force avoids pushing "
            "too hard on the ribs",
        },
        (sv, sp),
        (rv, rp),
        detail,
        reason_sim,
        reason_real,
    )


def _c7_side(runs: Mapping[str, Mapping], limits: ScanLimits):
    vsvf, cs, cf = (runs.get(k) for k in ("vs-vf", "cs", "cf"))
    if not _need(vsvf, "peak_force_N", "tank_min_J", "tank_power_min_W"):
        return None, None
    value: dict[str, Any] = {
        "n_contact_losses": vsvf.get("n_contact_losses"),
        "contact_loss_s": vsvf.get("contact_loss_s"),
        "fraction_at_k_min_during_loss": vsvf.get("fraction_at_k_min_during_loss"),
        "tank_min_J": vsvf["tank_min_J"],
        "tank_power_min_W": vsvf["tank_power_min_W"],
        "peak_force_vs_vf_N": vsvf["peak_force_N"],
        "peak_force_cs_N": cs.get("peak_force_N") if cs else None,
        "peak_force_cf_N": cf.get("peak_force_N") if cf else None,
    }
    checks = {
        "contact_lost": (vsvf.get("n_contact_losses") or 0) >= 1,
        "k_at_min_when_lost": (vsvf.get("fraction_at_k_min_during_loss") or 0.0)
        >= C7_MIN_FRACTION_AT_K_MIN,
        "tank_above_min": vsvf["tank_min_J"] >= limits.tank_min_J - C7_TANK_TOL_J,
        "power_valve": vsvf["tank_power_min_W"]
        >= -(1 + C7_POWER_TOL) * limits.power_max_W,
        "peak_below_cs": value["peak_force_cs_N"] is not None
        and vsvf["peak_force_N"] < value["peak_force_cs_N"],
        "peak_below_cf": value["peak_force_cf_N"] is not None
        and vsvf["peak_force_N"] < value["peak_force_cf_N"],
    }
    value["checks"] = checks
    return value, bool(all(checks.values()))


def claim_c7(
    sim: Mapping[str, Mapping] | None,
    real: Mapping[str, Mapping] | None,
    *,
    limits: ScanLimits | None = None,
    reason_sim: str | None = None,
    reason_real: str | None = None,
) -> Claim:
    """C7: disturbance runs: K -> K_min when contact is lost, power valve holds,
    T >= T_min, and VS-VF's peak force is below CS's and CF's.

    Args:
        sim, real: {"vs-vf": ..., "cs": ..., "cf": ...} scan_metrics of the
            disturbance runs. The real side needs a VS-VF disturbance log,
            which the published data lacks; the CS and CF peaks are then
            reported in ``detail`` only.
    """
    limits = ScanLimits() if limits is None else limits
    need = {"vs-vf": ("peak_force_N", "tank_min_J", "tank_power_min_W")}
    sv, sp = _c7_side(sim, limits) if sim else (None, None)
    rv, rp = _c7_side(real, limits) if real else (None, None)
    if sim and sv is None:
        reason_sim = _why_missing(sim, need)
    if real and rv is None and real.get("vs-vf") is not None:
        reason_real = _why_missing(real, need)
    detail = (
        f"K at min: K_z <= K_min + {C7_K_MIN_TOL_N_PER_M:g} N/m for >= "
        f"{C7_MIN_FRACTION_AT_K_MIN:.0%} of the loss time after {C7_LOSS_SETTLE_S:g} s; "
        f"valve: tank power >= -{1 + C7_POWER_TOL:g} P_max (P_max = "
        f"{limits.power_max_W:g} W); T >= T_min = {limits.tank_min_J:g} J"
    )
    if rv is None and real:
        peaks = {k: v.get("peak_force_N") for k, v in real.items() if v}
        detail += f"; real peak forces without a VS-VF disturbance log: {clean(peaks)}"
    return two_sided(
        "C7",
        "stiffness decreases to its minimum until re-contact; at re-contact the "
        "valves limit its growth; the tank is not emptied",
        (sv, sp),
        (rv, rp),
        detail,
        reason_sim,
        reason_real,
    )
