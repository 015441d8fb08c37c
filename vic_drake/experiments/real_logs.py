"""Scenarios of the real scan logs: controller, gains and target read from a log.

:func:`scenario_from_real_log` turns a real bag (``realdata.read_bag``) into
the :class:`~vic_drake.scenario.Scenario` that replays it on the measured
map: the controller (:func:`detect_controller`, or guessed from a CS/CF
log's name), its settings, the FDCC z gains (:func:`identify_fdcc_z_gains`)
and the target (the logged one as waypoints, or :func:`fit_target_profile`).
The settings the logs do not hold are the ``DEFAULT_*`` constants below.
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.identification import estimate_force_loop_gain
from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTACT_THRESHOLD_N
from vic_drake.scenario import (
    DisturbanceConfig,
    PhantomConfig,
    Scenario,
    TrajectoryConfig,
)

#: Stiffness QP weight R per VS controller when the log does not say, from the
#: data README: test_tracking5 (VS-CF) ran R = 0.1, test_nardi_matForce_lowR
#: (VS-VF) R = 1e-5.
DEFAULT_R = {"vs-cf": 0.1, "vs-vf": 1e-5}
#: The CS baseline's stiffness (test_compliance_control400), N/m.
DEFAULT_CS_STIFFNESS_N_PER_M = 400.0
#: The CF baseline's force reference (test_force_control), N.
DEFAULT_CF_FORCE_N = 7.0
#: FDCC z gains (k_p, k_d): FZI's defaults, which the paper kept for CS "due
#: to instability problems", and the paper's for the other controllers.
FZI_DEFAULT_FDCC_Z_GAINS = (0.05, 0.0005)
PAPER_FDCC_Z_GAINS = (0.3, 0.01)
#: FDCC z gains of the CS baseline (the paper's text).
CS_FDCC_Z_GAINS = FZI_DEFAULT_FDCC_Z_GAINS
#: FDCC z gains of the CF baseline. The paper's text gives k_p = 0.3 to every
#: controller but CS, yet the z loop gain identified from the CF logs
#: (analysis.identification.estimate_force_loop_gain) is that of FZI's defaults, as the CS
#: logs'; see docs/decisions.md, "CF baseline on FZI's default FDCC z gains".
CF_FDCC_Z_GAINS = FZI_DEFAULT_FDCC_Z_GAINS
#: The station's FDCC z loop gain per unit k_p, m/s/N: the slope G of
#: analysis.identification.estimate_force_loop_gain over k_p on CF scans of the measured map
#: (tests/experiments/test_real_logs.py checks it); see docs/decisions.md,
#: "FDCC z loop gain per k_p".
MODEL_LOOP_GAIN_PER_KP = 0.04
#: The 9-column CS/CF logs pair each pose with the force read 28 ticks (at
#: 500 Hz) later (data README); the simulated force is advanced by as much
#: before the comparison (analysis.real_comparison.lead_force).
REAL_SCAN_FORCE_DELAY_S = 28 * 0.002
#: Period at which a logged target is resampled into scenario waypoints, s.
#: The real target is piecewise linear with 1 cm/s slopes and one step
#: (the lift-off); see docs/decisions.md, "Waypoint resampling period".
WAYPOINT_PERIOD_S = 0.02


def detect_controller(real: pd.DataFrame) -> str:
    """VS-CF or VS-VF from a 31-column log.

    VS-VF when F_min,z reaches -9 N or F_ref,z varies in contact (more than
    0.5 N of spread); VS-CF when F_ref,z is constant in contact.
    """
    if real.attrs.get("layout") != "controller":
        raise VicDrakeError("detect_controller needs a 31-column controller log")
    contact = real["sensor_force_z_N"].to_numpy() < -CONTACT_THRESHOLD_N
    f_ref = real["force_ref_z_N"].to_numpy()[contact]
    f_min = real["force_min_z_N"].to_numpy()[contact]
    if f_ref.size == 0:
        raise VicDrakeError(
            "the log never touches the phantom; cannot tell its controller"
        )
    if np.any(np.isclose(f_min, -9.0, atol=1e-6)) or np.ptp(f_ref) > 0.5:
        return "vs-vf"
    return "vs-cf"


def _controller_from_name(name: str) -> tuple[str, float | None] | None:
    """(controller, setting) guessed from a CS/CF log's folder name, or None."""
    m = re.search(r"compliance_control(\d+)", name)
    if m:
        return "cs", float(m.group(1))
    if "compliance" in name:
        return "cs", None
    if "force_control" in name:
        return "cf", None
    return None


def _resampled_waypoints(real: pd.DataFrame, period_s: float = WAYPOINT_PERIOD_S):
    t = real["t_s"].to_numpy(float)
    grid = np.arange(t[0], t[-1] + 1e-9, period_s)
    rows = [grid] + [
        np.interp(grid, t, real[c].to_numpy(float)) for c in ("x_d_m", "y_d_m", "z_d_m")
    ]
    return np.column_stack(rows).tolist()


def fit_target_profile(real: pd.DataFrame) -> TrajectoryConfig:
    """The parametric target profile that reproduces a 31-column log's target.

    Reads the approach start, the times the target reaches the scan depth,
    starts and stops moving along x and jumps up (lift-off) from the logged
    x_d, z_d; the tip starts at the logged height. The log's target is
    exactly such a profile (see docs/decisions.md, "Parametric target fit"),
    and the fit keeps scenario files short; :func:`scenario_from_real_log` can also
    use the logged target itself (``waypoints=True``).
    """
    if real.attrs.get("layout") != "controller":
        raise VicDrakeError("fit_target_profile needs a 31-column controller log")
    t = real["t_s"].to_numpy(float)
    x_d, y_d, z_d = (real[c].to_numpy(float) for c in ("x_d_m", "y_d_m", "z_d_m"))
    z_scan = float(np.min(z_d))
    i_down = int(np.argmax(z_d <= z_scan + 1e-6))
    moving = np.abs(x_d - x_d[0]) > 1e-5
    i_x0 = int(np.argmax(moving)) if moving.any() else i_down
    x_end = float(np.min(x_d))
    i_x1 = int(np.argmax(x_d <= x_end + 1e-6))
    after = np.arange(t.size) > i_x1
    up = after & (z_d > z_scan + 1e-4)
    i_up = int(np.argmax(up)) if up.any() else t.size - 1
    approach_s = max(t[i_down] - t[0], 1e-3)
    scan_s = max(t[i_x1] - t[i_x0], 1e-3)
    return TrajectoryConfig(
        start_x_m=float(x_d[0]),
        end_x_m=x_end,
        y_m=float(np.median(y_d)),
        approach_z_m=float(z_d[0]),
        target_z_m=z_scan,
        approach_speed_m_per_s=float(max((z_d[0] - z_scan) / approach_s, 1e-4)),
        dwell_s=float(max(t[i_x0] - t[i_down], 0.0)),
        scan_speed_m_per_s=float(abs(x_d[0] - x_end) / scan_s),
        end_dwell_s=float(max(t[i_up] - t[i_x1], 0.0)),
        liftoff_height_m=float(max(np.max(z_d[after]) - z_scan, 0.0))
        if up.any()
        else 0.0,
        initial_tip_z_m=float(real["z_m"].iloc[0]),
    )


def identify_fdcc_z_gains(
    real: pd.DataFrame,
    *,
    stiffness_z_N_per_m: float,
    force_ref_N: float,
    fallback: tuple[float, float],
) -> dict:
    """The FDCC z gains a 9-column CS/CF log ran with, from its loop gain.

    The loop gain G is identified from the log
    (:func:`vic_drake.analysis.identification.estimate_force_loop_gain`, with the run's K_z
    and pressing-force reference) and the rig's two documented gain sets,
    :data:`FZI_DEFAULT_FDCC_Z_GAINS` and :data:`PAPER_FDCC_Z_GAINS`, are
    scored by ``|log(G / (MODEL_LOOP_GAIN_PER_KP k_p))|``; the nearer wins.
    When the identification is weak (R^2 < 0.5, G <= 0, too little contact)
    ``fallback`` is used.

    Args:
        real: ``realdata.read_bag`` of a 9-column log.
        stiffness_z_N_per_m: the run's K_z (CS: its stiffness; CF: 0).
        force_ref_N: the run's pressing-force reference, N (CS: 0).
        fallback: (k_p, k_d) used without a usable identification.

    Returns:
        dict with ``gains`` (k_p, k_d), ``identified`` (bool), and the
        estimate's ``gain_m_per_s_per_N`` and ``r2``.
    """
    est = estimate_force_loop_gain(
        real_to_canonical(real),
        stiffness_z_N_per_m=stiffness_z_N_per_m,
        force_ref_z_N=-force_ref_N,
    )
    g, r2 = est["gain_m_per_s_per_N"], est["r2"]
    out = {"gain_m_per_s_per_N": g, "r2": r2}
    if not (np.isfinite(g) and g > 0 and r2 >= 0.5):
        return {**out, "gains": tuple(fallback), "identified": False}
    sets = (FZI_DEFAULT_FDCC_Z_GAINS, PAPER_FDCC_Z_GAINS)
    best = min(
        sets, key=lambda kp_kd: abs(np.log(g / (MODEL_LOOP_GAIN_PER_KP * kp_kd[0])))
    )
    return {**out, "gains": tuple(best), "identified": True}


def scenario_from_real_log(
    real: pd.DataFrame,
    *,
    name: str,
    controller: str | None = None,
    stiffness_N_per_m: float | None = None,
    force_N: float | None = None,
    r_weight: float | None = None,
    disturbance: DisturbanceConfig | None = None,
    base: Scenario | None = None,
    waypoints: bool = True,
    fdcc_z_gains: tuple[float, float] | None = None,
) -> Scenario:
    """The scenario of a real scan on the measured map.

    31-column logs: controller from the log (:func:`detect_controller`) unless
    given; R from ``r_weight`` or :data:`DEFAULT_R`; VS-CF force reference
    from the logged F_ref (or ``force_N``); tank starting at the logged
    energy; the logged target as waypoints; the tip starting at the logged
    height. 9-column logs: ``controller`` ("cs" or "cf", else guessed from
    the name) with ``stiffness_N_per_m`` (CS, default 400) or ``force_N``
    (CF, default 7); the target at z = 0.085 moving along -x at 1 cm/s from
    the logged start for the log's duration; the tip starting at the logged
    pose; the FDCC z gains identified from the log
    (:func:`identify_fdcc_z_gains`; fallback CS :data:`CS_FDCC_Z_GAINS`, CF
    :data:`CF_FDCC_Z_GAINS`) unless ``fdcc_z_gains`` is given.

    Args:
        real: ``realdata.read_bag`` of the log (its own layout, not canonical).
        name: scenario name.
        disturbance: phantom lift (default none).
        base: scenario to start from (default: ``Scenario()``).
        waypoints: 31-column logs: replay the logged target as waypoints
            (True) or use its parametric fit (:func:`fit_target_profile`).
    """

    layout = real.attrs.get("layout")
    base = base or Scenario()
    duration = float(real["t_s"].iloc[-1])
    ctrl = base.controller
    fdcc = base.fdcc
    if layout == "controller":
        kind = controller or detect_controller(real)
        if kind not in ("cs", "cf", "vs-cf", "vs-vf"):
            raise VicDrakeError(
                f"--controller must be cs, cf, vs-cf or vs-vf; got {kind!r}"
            )
        contact = real["sensor_force_z_N"].to_numpy() < -CONTACT_THRESHOLD_N
        ref = replace(ctrl.reference, controller=kind)
        if kind == "vs-cf":
            logged = -float(np.median(real["force_ref_z_N"].to_numpy()[contact]))
            ref = replace(ref, force_ref_N=force_N or (logged if logged > 0 else 7.0))
        elif kind == "cf":
            ref = replace(ref, force_ref_N=force_N or DEFAULT_CF_FORCE_N)
        elif kind == "cs":
            k = stiffness_N_per_m or DEFAULT_CS_STIFFNESS_N_PER_M
            ref = replace(ref, constant_stiffness_N_per_m=[k, k, k])
        r = r_weight if r_weight is not None else DEFAULT_R.get(kind, 0.1)
        qp = replace(ctrl.qp, r_weight=[r, r, r])
        t0 = float(real["tank_energy_J"].iloc[0] - real["tank_delta_J"].iloc[0])
        tank = replace(ctrl.tank, initial_energy_J=t0)
        ctrl = replace(ctrl, reference=ref, qp=qp, tank=tank)
        if waypoints:
            trajectory = TrajectoryConfig(
                waypoints=_resampled_waypoints(real),
                initial_tip_z_m=float(real["z_m"].iloc[0]),
            )
        else:
            trajectory = fit_target_profile(real)
        description = f"real log {name}: {kind}, R = {r:g}, logged target"
    elif layout == "scan":
        guessed = _controller_from_name(name)
        if controller is None:
            if guessed is None:
                raise VicDrakeError(
                    f"cannot tell the controller of the 9-column log {name!r}; pass "
                    "--controller cs|cf (with --stiffness N_PER_M or --force N)"
                )
            kind = guessed[0]
        else:
            kind = controller
        if kind not in ("cs", "cf"):
            raise VicDrakeError(
                f"a 9-column log is a CS or CF scan; --controller must be cs or cf, got {kind!r}"
            )
        ref = replace(ctrl.reference, controller=kind)
        if kind == "cs":
            k = stiffness_N_per_m or (guessed[1] if guessed and guessed[1] else None)
            k = k or DEFAULT_CS_STIFFNESS_N_PER_M
            ref = replace(ref, constant_stiffness_N_per_m=[k, k, k])
            k_z, f_ref, fallback = k, 0.0, CS_FDCC_Z_GAINS
            description = f"real log {name}: CS at {k:g} N/m"
        else:
            ref = replace(ref, force_ref_N=force_N or DEFAULT_CF_FORCE_N)
            k_z, f_ref, fallback = 0.0, ref.force_ref_N, CF_FDCC_Z_GAINS
            description = f"real log {name}: CF at {ref.force_ref_N:g} N"
        if fdcc_z_gains is None:
            fdcc_z_gains = identify_fdcc_z_gains(
                real, stiffness_z_N_per_m=k_z, force_ref_N=f_ref, fallback=fallback
            )["gains"]
        fdcc = with_z_gains(fdcc, *fdcc_z_gains)
        description += (
            f", FDCC z gains k_p = {fdcc_z_gains[0]:g}, k_d = {fdcc_z_gains[1]:g}"
        )
        ctrl = replace(ctrl, reference=ref)
        x0, y0, z0 = (float(real[c].iloc[0]) for c in ("x_m", "y_m", "z_m"))
        z_target = float(real["z_target_m"].iloc[0])
        speed = 0.01
        trajectory = TrajectoryConfig(
            start_x_m=x0,
            end_x_m=x0 - speed * duration,
            y_m=y0,
            approach_z_m=z_target,
            target_z_m=z_target,
            scan_speed_m_per_s=speed,
            liftoff_height_m=0.0,
            initial_tip_z_m=z0,
        )
    else:
        raise VicDrakeError(
            f"log {name!r} has the {layout!r} layout; compare-real needs a scan log "
            "(31-column controller log or 9-column CS/CF log)"
        )
    return replace(
        base,
        name=name,
        description=description,
        phantom=PhantomConfig(
            kind="measured", lookup="bilinear", controller_lookup="nearest"
        ),
        controller=ctrl,
        fdcc=fdcc,
        trajectory=trajectory,
        disturbance=disturbance or DisturbanceConfig(),
        duration_s=duration,
    )


def with_z_gains(fdcc, p: float, d: float):
    """FDCC params with the z PD gains replaced (see CS_FDCC_Z_GAINS)."""
    p_gains, d_gains = list(fdcc.p_gains), list(fdcc.d_gains)
    p_gains[2], d_gains[2] = float(p), float(d)
    return replace(fdcc, p_gains=tuple(p_gains), d_gains=tuple(d_gains))


def nominal_sibling(bag: Path) -> Path | None:
    """The nominal log beside a ``*_dist`` log, if present."""
    if bag.name.endswith("_dist"):
        sibling = bag.with_name(bag.name[: -len("_dist")])
        if (sibling / "metadata.yaml").is_file():
            return sibling
    return None


__all__ = [
    "CF_FDCC_Z_GAINS",
    "CS_FDCC_Z_GAINS",
    "DEFAULT_CF_FORCE_N",
    "DEFAULT_CS_STIFFNESS_N_PER_M",
    "DEFAULT_R",
    "FZI_DEFAULT_FDCC_Z_GAINS",
    "MODEL_LOOP_GAIN_PER_KP",
    "PAPER_FDCC_Z_GAINS",
    "REAL_SCAN_FORCE_DELAY_S",
    "WAYPOINT_PERIOD_S",
    "detect_controller",
    "fit_target_profile",
    "identify_fdcc_z_gains",
    "nominal_sibling",
    "scenario_from_real_log",
    "with_z_gains",
]
