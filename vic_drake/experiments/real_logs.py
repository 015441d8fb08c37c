"""Scenarios of the real scan logs: controller, gains and target read from a log.

:func:`scenario_from_real_log` turns a real bag (``realdata.read_bag``) into
the :class:`~vic_drake.scenario.Scenario` that replays it on the measured
map: the controller and its settings identified from the log's signals
(:func:`identify_real_log`, :mod:`vic_drake.analysis.controller_id`) unless
the caller gives them, the FDCC z gains (:func:`identify_fdcc_z_gains`) and
the target (the logged one as waypoints, or :func:`fit_target_profile`).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.controller_id import (
    SCAN_FORCE_LAG_TICKS,
    ControllerIdentification,
    classify_vs_log,
    identify_controller,
)
from vic_drake.analysis.identification import estimate_force_loop_gain
from vic_drake.errors import VicDrakeError
from vic_drake.scenario import (
    DisturbanceConfig,
    PhantomConfig,
    Scenario,
    TrajectoryConfig,
)

#: The paper's settings of its four controllers (data README): the stiffness
#: QP weight R of the VS controllers (test_tracking5, VS-CF: 0.1;
#: test_nardi_matForce_lowR, VS-VF: 1e-5), the CS stiffness (N/m) and the
#: CF force (N). The synthetic scenarios (paper_scenarios) run them; a real
#: log's scenario reads its own from the log and uses these only for a CS or
#: CF controller forced onto a 31-column log, which holds neither setting.
DEFAULT_R = {"vs-cf": 0.1, "vs-vf": 1e-5}
DEFAULT_CS_STIFFNESS_N_PER_M = 400.0
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
REAL_SCAN_FORCE_DELAY_S = SCAN_FORCE_LAG_TICKS * 0.002
#: Period at which a logged target is resampled into scenario waypoints, s.
#: The real target is piecewise linear with 1 cm/s slopes and one step
#: (the lift-off); see docs/decisions.md, "Waypoint resampling period".
WAYPOINT_PERIOD_S = 0.02


def detect_controller(real: pd.DataFrame) -> str:
    """VS-CF or VS-VF from a 31-column log's reference laws.

    See :func:`vic_drake.analysis.controller_id.classify_vs_log`; raises
    VicDrakeError when the signals cannot tell.
    """
    if real.attrs.get("layout") != "controller":
        raise VicDrakeError("detect_controller needs a 31-column controller log")
    return classify_vs_log(real)[0]


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
    stiffness_z_N_per_m: float | None,
    force_ref_N: float,
    fallback: tuple[float, float],
) -> dict:
    """The FDCC z gains a real scan log ran with, from its loop gain.

    The loop gain G is identified from the log
    (:func:`vic_drake.analysis.identification.estimate_force_loop_gain`, with
    the run's K_z and the force reference that FDCC tracks). 9-column CS/CF
    logs: the rig's two documented gain sets, :data:`FZI_DEFAULT_FDCC_Z_GAINS`
    and :data:`PAPER_FDCC_Z_GAINS`, are scored by
    ``|log(G / (MODEL_LOOP_GAIN_PER_KP k_p))|``; the nearer wins. 31-column
    VS logs: neither set is near (docs/decisions.md, "FDCC z gains of the VS
    logs"), so ``k_p = G / MODEL_LOOP_GAIN_PER_KP`` with ``k_d`` in the
    fallback's ratio to ``k_p``. When the identification is weak (R^2 < 0.5,
    G <= 0, too little contact, or k_p outside [0.02, 1]) ``fallback`` is
    used.

    Args:
        real: ``realdata.read_bag`` of the log.
        stiffness_z_N_per_m: the run's K_z (CS: its stiffness; CF: 0); None
            for a 31-column log (its logged K_z).
        force_ref_N: the pressing-force reference FDCC tracks, N (CS and the
            VS controllers, whose force enters through K_z: 0).
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
    if real.attrs.get("layout") == "controller":
        k_p = g / MODEL_LOOP_GAIN_PER_KP
        if not 0.02 <= k_p <= 1.0:
            return {**out, "gains": tuple(fallback), "identified": False}
        k_d = k_p * fallback[1] / fallback[0]
        return {**out, "gains": (float(k_p), float(k_d)), "identified": True}
    sets = (FZI_DEFAULT_FDCC_Z_GAINS, PAPER_FDCC_Z_GAINS)
    best = min(
        sets, key=lambda kp_kd: abs(np.log(g / (MODEL_LOOP_GAIN_PER_KP * kp_kd[0])))
    )
    return {**out, "gains": tuple(best), "identified": True}


def identify_real_log(
    real: pd.DataFrame,
    *,
    controller: str | None = None,
    stiffness_N_per_m: float | None = None,
    force_N: float | None = None,
    r_weight: float | None = None,
) -> ControllerIdentification:
    """The controller and settings of a real scan log that the caller left open.

    Runs :func:`vic_drake.analysis.controller_id.identify_controller` for
    what is not given: the class when ``controller`` is None, then the
    settings the class needs (R; the VS-CF or CF force; the CS stiffness).
    R, and a 9-column log's setting, are not identified when given; the
    caller's settings override the identified ones in the scenario.

    Raises:
        VicDrakeError: a scan log of another layout, a controller the log
            cannot hold, or signals that cannot tell (the message names the
            option to pass).
    """
    layout = real.attrs.get("layout")
    if layout == "scan" and controller not in (None, "cs", "cf"):
        raise VicDrakeError(
            "a 9-column log is a CS or CF scan; --controller must be cs or cf, "
            f"got {controller!r}"
        )
    if controller is None:
        found = identify_controller(real, r_weight=r_weight)
        check_settings_apply(
            found.controller, False, stiffness_N_per_m, force_N, r_weight
        )
        return found
    check_settings_apply(controller, True, stiffness_N_per_m, force_N, r_weight)
    if layout == "controller" and controller in ("cs", "cf"):
        raise VicDrakeError(
            "a 31-column log is a variable-impedance scan (only the VS controllers "
            f"logged it); --controller must be vs-cf or vs-vf, got {controller!r}"
        )
    setting = {"cs": stiffness_N_per_m, "cf": force_N}.get(controller)
    if layout == "scan" and setting is not None:
        return ControllerIdentification(controller, given=True)
    return identify_controller(real, controller=controller, r_weight=r_weight)


#: The settings each controller takes: (argument name, command-line option,
#: the controllers it applies to).
_SETTINGS = (
    ("stiffness_N_per_m", "--stiffness", ("cs",)),
    ("force_N", "--force", ("cf", "vs-cf")),
    ("r_weight", "--R", ("vs-cf", "vs-vf")),
)


def check_settings_apply(
    controller: str,
    given: bool,
    stiffness_N_per_m: float | None,
    force_N: float | None,
    r_weight: float | None,
) -> None:
    """Refuses a setting that the controller does not have (it would be ignored).

    Args:
        controller: the controller that runs.
        given: it was given (else identified from the log).

    Raises:
        VicDrakeError: "--stiffness applies to CS; this log was identified as
            vs-cf (pass --controller cs)", or, with ``given``, "... not to the
            given controller vs-cf".
    """
    values = {
        "stiffness_N_per_m": stiffness_N_per_m,
        "force_N": force_N,
        "r_weight": r_weight,
    }
    for name, option, applies in _SETTINGS:
        if values[name] is None or controller in applies:
            continue
        to = " and ".join(c.upper() for c in applies)
        if given:
            raise VicDrakeError(
                f"{option} applies to {to}, not to the given controller {controller}; "
                f"drop {option} or pass --controller {' or '.join(applies)}"
            )
        raise VicDrakeError(
            f"{option} applies to {to}; this log was identified as {controller} "
            f"(pass --controller {' or '.join(applies)} to run that instead, or drop "
            f"{option})"
        )


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
    identification: ControllerIdentification | None = None,
) -> Scenario:
    """The scenario of a real scan on the measured map.

    The controller and the settings the caller does not give (``controller``,
    ``stiffness_N_per_m`` for CS, ``force_N`` for CF and VS-CF, ``r_weight``
    for VS) are identified from the log's signals (:func:`identify_real_log`);
    the description says what was identified and on what evidence.

    31-column logs: VS-CF force reference, VS-VF eps_d and F_min,z, R, and
    the settings the log holds every tick (K_z bounds, T_min, power limit,
    eps_max) from the log; tank starting at the logged energy; the logged
    target as waypoints; the tip starting at the logged height. A CS or CF
    controller forced onto such a log runs :data:`DEFAULT_CS_STIFFNESS_N_PER_M`
    or :data:`DEFAULT_CF_FORCE_N` unless given. 9-column logs (CS or CF):
    the target at the logged z_target moving along -x at 1 cm/s from the
    logged start for the log's duration; the tip starting at the logged
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
        identification: the result of :func:`identify_real_log` with the
            same arguments, when the caller already has it.

    Raises:
        VicDrakeError: see :func:`identify_real_log`.
    """
    layout = real.attrs.get("layout")
    if layout not in ("controller", "scan"):
        raise VicDrakeError(
            f"log {name!r} has the {layout!r} layout; compare-real needs a scan log "
            "(31-column controller log or 9-column CS/CF log)"
        )
    if identification is None:
        identification = identify_real_log(
            real,
            controller=controller,
            stiffness_N_per_m=stiffness_N_per_m,
            force_N=force_N,
            r_weight=r_weight,
        )
    kind = identification.controller
    found = identification.settings
    given = []

    def pick(value, key, option, fallback=None):
        if value is not None:
            given.append((key, value))
            return float(value)
        if key in found:
            return float(found[key])
        if fallback is None:
            raise VicDrakeError(
                f"the log {name!r} does not give the {kind} controller's {key}; pass "
                f"{option}"
            )
        return float(fallback)

    base = base or Scenario()
    duration = float(real["t_s"].iloc[-1])
    ctrl = base.controller
    fdcc = base.fdcc
    ref = replace(ctrl.reference, controller=kind)
    if kind == "cs":
        k = pick(
            stiffness_N_per_m, "stiffness_N_per_m", "--stiffness N_PER_M",
            DEFAULT_CS_STIFFNESS_N_PER_M if layout == "controller" else None,
        )  # fmt: skip
        ref = replace(ref, constant_stiffness_N_per_m=[k, k, k])
    elif kind in ("cf", "vs-cf"):
        fallback = (
            DEFAULT_CF_FORCE_N if kind == "cf" and layout == "controller" else None
        )
        ref = replace(
            ref, force_ref_N=pick(force_N, "force_ref_N", "--force N", fallback)
        )
    if layout == "controller":
        if kind == "vs-vf" and "eps_d_m" in found:
            ref = replace(
                ref, eps_d_m=found["eps_d_m"], force_min_z_N=found["force_min_z_N"]
            )
        if "eps_max_m" in found:
            ref = replace(ref, eps_max_m=found["eps_max_m"])
        qp = ctrl.qp
        if kind in ("vs-cf", "vs-vf"):
            r = pick(r_weight, "r_weight", "--R R")
            qp = replace(qp, r_weight=[r, r, r])
        k_lo, k_hi = list(qp.stiffness_min_N_per_m), list(qp.stiffness_max_N_per_m)
        k_lo[2] = found.get("stiffness_z_min_N_per_m", k_lo[2])
        k_hi[2] = found.get("stiffness_z_max_N_per_m", k_hi[2])
        qp = replace(qp, stiffness_min_N_per_m=k_lo, stiffness_max_N_per_m=k_hi)
        t0 = float(real["tank_energy_J"].iloc[0] - real["tank_delta_J"].iloc[0])
        tank = replace(
            ctrl.tank,
            initial_energy_J=t0,
            min_energy_J=found.get("tank_min_J", ctrl.tank.min_energy_J),
            power_limit_W=-found.get("power_limit_W", -ctrl.tank.power_limit_W),
        )
        ctrl = replace(ctrl, reference=ref, qp=qp, tank=tank)
        if fdcc_z_gains is None:
            fdcc_z_gains = identify_fdcc_z_gains(
                real,
                stiffness_z_N_per_m=None,
                force_ref_N=0.0,
                fallback=PAPER_FDCC_Z_GAINS,
            )["gains"]
        fdcc = with_z_gains(fdcc, *fdcc_z_gains)
        if waypoints:
            trajectory = TrajectoryConfig(
                waypoints=_resampled_waypoints(real),
                initial_tip_z_m=float(real["z_m"].iloc[0]),
            )
        else:
            trajectory = fit_target_profile(real)
        tail = (
            f", logged target, FDCC z gains k_p = {fdcc_z_gains[0]:.3g}, "
            f"k_d = {fdcc_z_gains[1]:.3g}"
        )
    else:
        if kind == "cs":
            k_z, f_ref, fallback = (
                ref.constant_stiffness_N_per_m[2],
                0.0,
                CS_FDCC_Z_GAINS,
            )
        else:
            k_z, f_ref, fallback = 0.0, ref.force_ref_N, CF_FDCC_Z_GAINS
        if fdcc_z_gains is None:
            fdcc_z_gains = identify_fdcc_z_gains(
                real, stiffness_z_N_per_m=k_z, force_ref_N=f_ref, fallback=fallback
            )["gains"]
        fdcc = with_z_gains(fdcc, *fdcc_z_gains)
        tail = f", FDCC z gains k_p = {fdcc_z_gains[0]:g}, k_d = {fdcc_z_gains[1]:g}"
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
    description = f"real log {name}: {identification.summary()}"
    if given:
        description += "; given " + ", ".join(f"{k} = {v:g}" for k, v in given)
    return replace(
        base,
        name=name,
        description=description + tail,
        phantom=PhantomConfig(
            kind="measured", lookup="bilinear", controller_lookup="bilinear"
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
    "check_settings_apply",
    "detect_controller",
    "fit_target_profile",
    "identify_fdcc_z_gains",
    "identify_real_log",
    "nominal_sibling",
    "scenario_from_real_log",
    "with_z_gains",
]
