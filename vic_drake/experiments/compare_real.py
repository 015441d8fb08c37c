"""A real scan replayed in simulation and compared with its log.

:func:`compare_real` builds the scenario of a real bag
(:func:`~vic_drake.experiments.real_logs.scenario_from_real_log`), estimates
the phantom's motion from the log and replays it when it is significant
(:func:`~vic_drake.analysis.phantom_motion.motion_is_significant`), simulates
it (:func:`~vic_drake.experiments.scan_run.run_scan`) and reduces both runs
to the same metrics; ``vic-drake compare-real`` is a thin wrapper around it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.contact import scan_window
from vic_drake.analysis.identification import estimate_force_loop_gain
from vic_drake.analysis.phantom_motion import (
    estimate_phantom_motion,
    map_surface_error_m,
    motion_significance,
    replay_table,
)
from vic_drake.analysis.real_comparison import compare_contact_loss, compare_with_real
from vic_drake.control.references import has_tank
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.lateral_replay import (
    AUTO,
    check_lateral_passes,
    corrected_waypoints,
    lateral_rms_mm,
    resolve_lateral_passes,
)
from vic_drake.experiments.real_logs import (
    REAL_SCAN_FORCE_DELAY_S,
    identify_real_log,
    nominal_sibling,
    scenario_from_real_log,
)
from vic_drake.experiments.scan_run import run_scan
from vic_drake.experiments.surface_calibration import (
    parse_surface_offset,
    placed_surface,
    surface_calibration,
)
from vic_drake.realdata import read_bag
from vic_drake.scenario import DisturbanceConfig, TrajectoryConfig
from vic_drake.station.params import StationParams
from vic_drake.tissue import TISSUE_LAWS
from vic_drake.tissue.phantom import load_phantom
from vic_drake.tissue.phantom.distorted import (
    with_map_errors,
    with_surface_plane,
    with_surface_profile,
)
from vic_drake.tissue.relaxation import RelaxationParams, tissue_relaxation


def phantom_replay(bag: Path, real, phantom):
    """The phantom's motion in a real scan and the table that replays it.

    The motion (:func:`~vic_drake.analysis.phantom_motion.estimate_phantom_motion`)
    is estimated against the nominal sibling log when one exists
    (:func:`~vic_drake.experiments.real_logs.nominal_sibling`), else the map;
    the table (:func:`~vic_drake.analysis.phantom_motion.replay_table`) is
    empty unless the motion is significant, and with a sibling it carries the
    map's surface error under the track that the sibling measures.

    Args:
        bag: the log's folder.
        real: its canonical frame (``real_to_canonical``).
        phantom: the measured map.

    Returns:
        (motion DataFrame, table ``[[t_s, z_offset_m], ...]`` or ``[]``,
        map surface error per sample in m or None without a sibling).
    """
    sibling = nominal_sibling(Path(bag))
    nominal = real_to_canonical(read_bag(sibling)) if sibling else None
    motion = estimate_phantom_motion(real, phantom, nominal=nominal)
    surface_error = (
        map_surface_error_m(real, phantom, nominal) if nominal is not None else None
    )
    return motion, replay_table(motion, surface_error_m=surface_error), surface_error


def check_duration_reaches_window(real, duration_s: float | None) -> None:
    """Refuses, before simulating, a duration that ends before the real log's
    contact window (where the comparison is made: first contact + 1 s until
    the final lift, :func:`~vic_drake.analysis.contact.scan_window`), or more
    than a second past the log's end.

    Raises:
        VicDrakeError: naming the window and the log's length.
    """
    if duration_s is None:
        return
    t = real["t_s"].to_numpy(float)
    if duration_s > float(t[-1]) + 1.0:  # Past the log there is nothing to compare.
        raise VicDrakeError(
            f"duration {duration_s:g} s runs past the real log's end "
            f"({float(t[-1]):.1f} s), where there is nothing to compare; give at "
            f"most {float(t[-1]) + 1.0:.1f} s, or leave it out for the whole log"
        )
    window = scan_window(real)
    if not window.any():
        return  # compare_with_real names a log without a window.
    start, end = float(t[window][0]), float(t[window][-1])
    if duration_s <= start:
        raise VicDrakeError(
            f"duration {duration_s:g} s ends before the real log's contact window "
            f"({start:.2f}-{end:.2f} s: first contact + 1 s until the final lift), "
            f"where the runs are compared; simulate longer than {start:.2f} s (the "
            f"whole log, the default, is {float(t[-1]):.1f} s)"
        )


def compare_real(
    bag_dir,
    *,
    controller: str | None = None,
    stiffness_N_per_m: float | None = None,
    force_N: float | None = None,
    r_weight: float | None = None,
    data_dir=None,
    duration_s: float | None = None,
    tissue_law: str | None = None,
    relaxation: RelaxationParams | None = None,
    surface_offset: float | str | None = None,
    lateral_passes: int | str = AUTO,
    progress=None,
    return_frames: bool = False,
):
    """Simulates a real experiment on the measured map and compares it with its log.

    See :func:`scenario_from_real_log` for how the scenario is built. The
    phantom's motion is estimated from every log
    (:func:`vic_drake.analysis.phantom_motion.estimate_phantom_motion`,
    against the nominal sibling log when it exists, else the map) and
    replayed as the scenario's disturbance table when it is significant
    (:func:`vic_drake.analysis.phantom_motion.replay_table`; with a sibling,
    plus the map's surface error under the track that the sibling measures,
    :func:`vic_drake.analysis.phantom_motion.map_surface_error_m`);
    contact losses of both runs are compared.
    Alignment: :func:`vic_drake.analysis.real_comparison.compare_with_real`.
    ``surface_offset`` raises the simulated tissue above the published map:
    a number of m, "auto", "placement", "anchors" or "none", None for
    :data:`~vic_drake.experiments.surface_calibration.DEFAULT_SURFACE_OFFSET`
    (:func:`~vic_drake.experiments.surface_calibration.surface_calibration`;
    "placement", auto's mode, places the published map by the plane of the
    log's in-contact surface when the motion is not replayed,
    :func:`~vic_drake.experiments.surface_calibration.placed_surface`);
    the controller keeps reading the published map.
    ``lateral_passes`` (0 to 3, or "auto", the default: one when the motion
    is replayed, else none) reruns the scan that many times, each with the
    target moved by the previous run's lateral error against the real tip
    (:func:`~vic_drake.experiments.lateral_replay.corrected_waypoints`), so the
    simulated tip crosses the map where the real one did and the replayed
    surface, measured under the real tip, is the one under it; the metrics
    are those of the last run.

    Returns:
        dict with the contract keys controller, duration_s, force_rmse_N,
        force_peak_err_N, z_rmse_mm, kz_corr, tank_min_J, rtf, and more
        (time offset, window, peaks, means, the motion's figures
        ``phantom_motion_*``; ``lift_*`` when replayed (``lift_max_mm``: the
        replayed table's highest offset); ``map_surface_error_max_mm`` with a
        sibling; and the contact-loss
        figures of :func:`vic_drake.analysis.real_comparison.compare_contact_loss`).
        ``controller_identified`` holds what was identified from the log
        (:func:`~vic_drake.experiments.real_logs.identify_real_log`) and
        ``tissue_law`` the simulated tissue's law ("relaxing" unless
        ``tissue_law`` says "hc"). ``relaxation`` replaces the relaxing
        law's branches (default :data:`~vic_drake.tissue.DEFAULT_RELAXATION`)
        in the simulated tissue and in the surface calibration's lift-off
        correction; it is echoed as ``tissue_relaxation`` (appended last).
        ``surface_offset_mm`` is the offset
        applied, ``surface_offset_source`` where it came from; the log's
        evidence: ``surface_first_contact_mm`` (and its ``_sigma_mm``),
        ``controller_map_offset_mm``, the lift-off's
        ``surface_lift_off_mm`` (``_sigma_mm``, ``_kappa_scale``,
        ``_speed_mm_per_s``) (None when the log holds none); with a profile
        (source "first contact + lift-off") ``surface_profile_x_m`` and
        ``surface_profile_offset_mm`` (its two anchors; ``surface_offset_mm``
        is then their mean), else None. ``lateral_passes`` (the number run)
        and ``lateral_rms_mm`` (per run, the RMS horizontal distance between
        the tips over the real scan window) are appended, then the placement
        plane the log gives (whether applied or not; source "placement" when
        applied, ``surface_offset_mm`` then its offset at its origin):
        ``surface_placement_offset_mm`` (``_sigma_mm``),
        ``surface_placement_slope_mm_per_m`` (``_sigma_mm_per_m``; the rise
        along ``surface_placement_direction``), ``surface_placement_origin_m``
        and ``surface_placement_residual_rms_mm`` (None without a plane).
        With ``return_frames``: (dict, sim DataFrame, real canonical DataFrame).
    """
    bag = Path(bag_dir)
    if not bag.exists():
        raise VicDrakeError(f"bag {str(bag)!r} does not exist; pass a ROS 2 bag folder")
    raw = read_bag(bag)
    if bag.is_file():
        bag = bag.parent
    if raw.attrs["layout"] not in ("controller", "scan"):
        raise VicDrakeError(
            f"bag {str(bag)!r} has the {raw.attrs['layout']!r} layout "
            f"({raw.shape[1]} columns); compare-real needs a scan log: 31 columns "
            "(VS controller) or 9 columns (CS/CF)"
        )
    if tissue_law is not None and tissue_law not in TISSUE_LAWS:
        raise VicDrakeError(
            f"tissue_law must be one of {list(TISSUE_LAWS)}; got {tissue_law!r}"
        )
    law = tissue_law if tissue_law is not None else StationParams().tissue_law
    if relaxation is not None:
        if not isinstance(relaxation, RelaxationParams):
            raise VicDrakeError(
                "relaxation must be a RelaxationParams or None; got "
                f"{type(relaxation).__name__}"
            )
        if law != "relaxing":
            raise VicDrakeError(
                f"a relaxation needs the 'relaxing' tissue law; got {law!r}"
            )
    surface_offset = parse_surface_offset(surface_offset)
    lateral_passes = check_lateral_passes(lateral_passes)
    # The controller first: a log whose signals cannot tell fails before the
    # motion estimate and the simulation.
    identification = identify_real_log(
        raw,
        controller=controller,
        stiffness_N_per_m=stiffness_N_per_m,
        force_N=force_N,
        r_weight=r_weight,
    )
    real = real_to_canonical(raw)
    check_duration_reaches_window(real, duration_s)
    published = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    surface = surface_calibration(
        real,
        published,
        surface_offset,
        relaxation=tissue_relaxation(law) if relaxation is None else relaxation,
    )
    profile = surface["profile"]
    # The simulated tissue: the published map raised by the offset (or the
    # profile; the controller then reads the published map itself).
    if profile is None:
        phantom = with_map_errors(published, surface_offset_m=surface["offset_m"])
    else:
        phantom = with_surface_profile(published, profile["x_m"], profile["offset_m"])
    motion, table, surface_error = phantom_replay(bag, real, phantom)
    replay = bool(table)
    # A resting phantom: its placement plane, when the mode asks for it.
    surface = placed_surface(surface, resting=not replay)
    plane = surface["plane"]
    if plane is not None:
        phantom = with_surface_plane(published, **plane)
    # The simulated tissue is a reshaped map (profile or plane): the controller
    # reads the published one, as the real controller read its own.
    own_surface = profile is not None or plane is not None
    lateral_passes = resolve_lateral_passes(lateral_passes, replayed=replay)
    disturbance = DisturbanceConfig(table=table) if replay else None
    lift_m = motion["phantom_lift_m"].to_numpy()
    motion_info = {
        "phantom_motion_max_mm": float(1e3 * np.max(np.abs(lift_m))),
        "phantom_motion_sigma_median_mm": float(
            1e3 * np.median(motion["phantom_lift_sigma_m"])
        ),
        "phantom_motion_significance": motion_significance(motion),
        "phantom_motion_replayed": bool(replay),
        "phantom_motion_reference": motion.attrs["reference"],
    }
    if replay:
        motion_info["lift_max_mm"] = float(1e3 * max(row[1] for row in table))
        motion_info["lift_reference"] = motion.attrs["reference"]
    if surface_error is not None:
        motion_info["map_surface_error_max_mm"] = float(
            1e3 * np.max(np.abs(surface_error))
        )
    scenario = scenario_from_real_log(
        raw,
        name=bag.name,
        controller=controller,
        stiffness_N_per_m=stiffness_N_per_m,
        force_N=force_N,
        r_weight=r_weight,
        disturbance=disturbance,
        identification=identification,
    )
    if tissue_law is not None:
        scenario.station.tissue_law = tissue_law
    if relaxation is not None:
        scenario.station = scenario.station.with_relaxation(relaxation)
    if surface["offset_m"] != 0.0 and not own_surface:
        # The controller reads the published map, as the real one read its own.
        scenario.variations.map_errors.surface_offset_m = -surface["offset_m"]
    if tissue_law is not None or relaxation is not None or surface["offset_m"] != 0.0:
        scenario.validate()
    if progress:
        progress(scenario.description)
    extra = {"controller_phantom": published} if own_surface else {}
    result = run_scan(
        scenario, phantom=phantom, duration_s=duration_s, progress=progress, **extra
    )
    window = scan_window(real)
    lateral_rms = [lateral_rms_mm(result.df, real, window)]
    for n in range(1, lateral_passes + 1):
        if progress:
            progress(
                f"lateral pass {n} of {lateral_passes}: the path corrected by the "
                f"last run's lateral error ({lateral_rms[-1]:.2f} mm RMS)"
            )
        start_z = scenario.trajectory.initial_tip_z_m
        if start_z is None:
            start_z = scenario.trajectory.approach_z_m
        scenario.trajectory = TrajectoryConfig(
            waypoints=corrected_waypoints(result.df, real), initial_tip_z_m=start_z
        )
        result = run_scan(
            scenario, phantom=phantom, duration_s=duration_s, progress=progress, **extra
        )
        lateral_rms.append(lateral_rms_mm(result.df, real, window))
    lead = REAL_SCAN_FORCE_DELAY_S if raw.attrs["layout"] == "scan" else 0.0
    metrics = compare_with_real(result.df, real, force_lead_s=lead)
    unaligned = compare_with_real(result.df, real, force_lead_s=lead, align=False)
    out = {
        "controller": scenario.controller.reference.controller,
        "duration_s": result.sim_s,
        "force_rmse_N": metrics["force_rmse_N"],
        "force_peak_err_N": metrics["force_peak_err_N"],
        "z_rmse_mm": metrics["z_rmse_mm"],
        "kz_corr": metrics["kz_corr"],
        "tank_min_J": metrics["tank_min_J"]
        if has_tank(scenario.controller.reference)
        else None,
        "rtf": result.rtf,
    }
    out["rtf_cpu"] = result.sim_s / result.cpu_s if result.cpu_s > 0 else None
    # The same figures without the time shift, so a shift at its bound or a
    # weak correlation cannot flatter the comparison unseen.
    out["force_rmse_unaligned_N"] = unaligned["force_rmse_N"]
    out["z_rmse_unaligned_mm"] = unaligned["z_rmse_mm"]
    out.update(
        {k: v for k, v in metrics.items() if k not in out},
        log=str(bag),
        layout=raw.attrs["layout"],
    )
    # The FDCC z loop gain of the real log and of the simulation (see
    # analysis.identification.estimate_force_loop_gain): how alike the two force loops are.
    kind = scenario.controller.reference.controller
    constant_k = (
        scenario.controller.reference.constant_stiffness_N_per_m[2]
        if kind == "cs"
        else (0.0 if kind == "cf" else None)
    )
    fdcc_target = -scenario.controller.reference.force_ref_N if kind == "cf" else 0.0
    for label, frame in (("real", real), ("sim", result.df)):
        est = estimate_force_loop_gain(
            frame, stiffness_z_N_per_m=constant_k, force_ref_z_N=fdcc_target
        )
        out[f"force_loop_gain_{label}"] = est["gain_m_per_s_per_N"]
    out["fdcc_z_gains"] = [scenario.fdcc.p_gains[2], scenario.fdcc.d_gains[2]]
    out.update(motion_info)
    out["controller_identified"] = identification.as_dict()
    out["tissue_law"] = scenario.station.tissue_law
    out.update(_surface_keys(surface))
    seen = real[real["t_s"] <= result.df["t_s"].iloc[-1] + metrics["time_offset_s"]]
    out.update(compare_contact_loss(result.df, seen))
    # Added after the keys of earlier versions, whose order is kept.
    out.update(_lift_off_keys(surface["lift_off"], surface["profile"]))
    out["lateral_passes"] = lateral_passes
    out["lateral_rms_mm"] = lateral_rms
    out.update(_placement_keys(surface["placement"]))
    if relaxation is not None:
        out["tissue_relaxation"] = relaxation.as_dict()
    if return_frames:
        return out, result.df, real
    return out


def _surface_keys(surface: dict) -> dict:
    """compare-real's surface-calibration keys (mm)."""
    first = surface["first_contact"]
    ctrl = surface["controller_map_offset_m"]
    return {
        "surface_offset_mm": 1e3 * surface["offset_m"],
        "surface_offset_source": surface["source"],
        "surface_first_contact_mm": None if first is None else 1e3 * first.offset_m,
        "surface_first_contact_sigma_mm": None
        if first is None
        else 1e3 * first.sigma_m,
        "controller_map_offset_mm": None if ctrl is None else 1e3 * ctrl,
    }


def _lift_off_keys(lift, profile) -> dict:
    """compare-real's lift-off and profile keys (mm; None where absent)."""
    keys = ("mm", "sigma_mm", "kappa_scale", "speed_mm_per_s")
    out = {f"surface_lift_off_{k}": None for k in keys}
    if lift is not None:
        out.update(
            surface_lift_off_mm=1e3 * lift.offset_m,
            surface_lift_off_sigma_mm=1e3 * lift.sigma_m,
            surface_lift_off_kappa_scale=lift.kappa_scale,
            surface_lift_off_speed_mm_per_s=1e3 * lift.speed_m_per_s,
        )
    out["surface_profile_x_m"] = None if profile is None else list(profile["x_m"])
    out["surface_profile_offset_mm"] = (
        None if profile is None else [1e3 * v for v in profile["offset_m"]]
    )
    return out


def _placement_keys(placement) -> dict:
    """compare-real's placement-plane keys (mm, mm/m; None without a plane)."""
    names = (
        "offset_mm",
        "offset_sigma_mm",
        "slope_mm_per_m",
        "slope_sigma_mm_per_m",
        "origin_m",
        "direction",
        "residual_rms_mm",
    )
    if placement is None:
        return {f"surface_placement_{k}": None for k in names}
    p = placement
    values = (
        1e3 * p.offset_m,
        1e3 * p.offset_sigma_m,
        1e3 * p.slope_m_per_m,
        1e3 * p.slope_sigma_m,
        [p.x0_m, p.y0_m],
        list(p.direction),
        1e3 * p.residual_rms_m,
    )
    return {f"surface_placement_{k}": v for k, v in zip(names, values)}


__all__ = ["compare_real", "phantom_replay"]
