"""``vic-drake scan`` and ``vic-drake compare-real``: closed-loop scans.

- ``scan SCENARIO.yaml``: simulates a scenario file (``diagrams/*.yaml``)
  and prints its scan metrics; ``--out`` stores the log (parquet or csv) and
  the exact scenario beside it; ``--bag DIR`` writes the log as a ROS 2 bag
  in the real rig's layout.
- ``compare-real BAG_DIR``: builds the scenario of a real scan log on the
  measured map, simulates it, aligns it with the log and prints the
  comparison (see :func:`vic_drake.experiments.compare_real`).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from vic_drake.commands.common import (
    Progress,
    add_data_dir_option,
    add_json_option,
    bag_path,
    emit,
    parse_relaxation,
)
from vic_drake.commands.scan_summary import (
    SCAN_DESCRIPTION,
    scan_human_summary,
    scan_metrics_dict,
)
from vic_drake.errors import VicDrakeError
from vic_drake.paths import PLOT_SUFFIXES, check_output_file, scenario_path
from vic_drake.run_limits import MAX_EXTRA_DURATION_S, check_scan_duration


def _positive(value: str, option: str) -> float:
    try:
        v = float(value)
    except ValueError:
        raise VicDrakeError(f"{option} takes a number > 0; got {value!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise VicDrakeError(f"{option} takes a number > 0; got {value!r}")
    return v


def _count(value: str) -> int | str:
    """--lateral-passes: an integer from 0 to MAX_LATERAL_PASSES, or "auto"."""
    from vic_drake.experiments.lateral_replay import (
        AUTO,
        MAX_LATERAL_PASSES,
        check_lateral_passes,
    )

    try:
        return check_lateral_passes(AUTO if value == AUTO else int(value))
    except (ValueError, VicDrakeError):
        raise VicDrakeError(
            f"--lateral-passes takes an integer from 0 to {MAX_LATERAL_PASSES} "
            f"or '{AUTO}'; got {value!r}"
        ) from None


def _surface_offset(value: str):
    """--surface-offset: one of SURFACE_OFFSET_MODES or a number of mm (returned in m)."""
    from vic_drake.experiments.surface_calibration import (
        MAX_SURFACE_OFFSET_M,
        SURFACE_OFFSET_MODES,
    )

    if value in SURFACE_OFFSET_MODES:
        return value
    try:
        v = float(value)
    except ValueError:
        v = math.nan
    if not (math.isfinite(v) and abs(v) <= 1e3 * MAX_SURFACE_OFFSET_M):
        raise VicDrakeError(
            f"--surface-offset takes {' or '.join(SURFACE_OFFSET_MODES)} or a number "
            f"of mm within +-{1e3 * MAX_SURFACE_OFFSET_M:g}; got {value!r}"
        )
    return v * 1e-3


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "compare-real",
        help="simulate a real scan experiment on the measured map and compare with its log",
        description=(
            "The controller and its settings are identified from the log's signals "
            "unless given (never from the folder name). 31-column logs (VS "
            "controllers): VS-CF when F_ref,z is one constant in contact, VS-VF when it "
            "follows the map law; R read off the logged K_z and confirmed by replaying "
            "the stiffness QP; the logged target as reference. 9-column logs (CS/CF): "
            "the contact force regressed on the target-to-tip error, f = K e (CS, its "
            "stiffness) or f = f_ref (CF, its force); the target at the logged z_target "
            "moving along -x at 1 cm/s from the logged start. When the signals cannot "
            "tell, the command stops and asks for --controller and the setting "
            "(--stiffness, --force, --R). *_dist logs: the "
            "phantom lift is estimated from the log and replayed, and contact losses "
            "are compared. The simulated record is shifted by up to 0.5 s to maximise "
            "the force cross-correlation, then compared over the real log's contact "
            "window (first contact + 1 s to last contact)."
        ),
    )
    p.add_argument(
        "bag_dir",
        metavar="BAG_DIR",
        help="ROS 2 bag folder of a scan (absolute, relative, or relative to the "
        "data folder, e.g. experiments/test_tracking5)",
    )
    p.add_argument(
        "--controller",
        choices=("cs", "cf", "vs-cf", "vs-vf"),
        default=None,
        help="controller to simulate (default: identified from the log's signals)",
    )
    p.add_argument(
        "--stiffness",
        metavar="N_PER_M",
        default=None,
        help="CS stiffness, N/m (default: identified from the log; an error for "
        "another controller)",
    )
    p.add_argument(
        "--force",
        metavar="N",
        default=None,
        help="CF / VS-CF force reference, N (default: identified from the log; an "
        "error for another controller)",
    )
    p.add_argument(
        "--R",
        dest="r_weight",
        metavar="R",
        default=None,
        help="stiffness QP weight R of VS-CF / VS-VF (> 0; default: identified from "
        "the log; an error for another controller)",
    )
    p.add_argument(
        "--duration",
        metavar="S",
        default=None,
        help="simulate only the first S seconds (default: the whole log); must "
        "reach into the log's contact window",
    )
    p.add_argument(
        "--tissue-law",
        choices=("relaxing", "hc"),
        default=None,
        help="the simulated tissue: Hunt-Crossley with stress relaxation (default) "
        "or plain Hunt-Crossley",
    )
    p.add_argument(
        "--relaxation",
        metavar="G:TAU[,G:TAU...]",
        default=None,
        help="branches of the relaxing law (fraction g, time constant tau in s), "
        "in the simulated tissue and the lift-off correction (default: "
        "vic_drake.tissue.DEFAULT_RELAXATION, 0.08:22.9)",
    )
    p.add_argument(
        "--surface-offset",
        metavar="MM|auto|placement|anchors|none",
        default=None,
        help="raise the simulated tissue above the published map: a number of mm; "
        "'placement' (the plane of the log's in-contact surface, offset and tilt "
        "along the track, when the phantom rests, else the anchors); 'anchors' "
        "(the log's first contact from free space and its final lift-off, a "
        "profile along x when both are plausible, else the one that is, else the "
        "rig's default); 'auto' (the default: placement); or 'none'; the "
        "controller keeps reading the published map",
    )
    p.add_argument(
        "--lateral-passes",
        metavar="N",
        default=None,
        help="rerun the scan N times (0-3, or 'auto', the default: 1 when the "
        "phantom's motion is replayed, else 0), each with the target moved "
        "by the previous run's lateral error against the real tip, so the "
        "simulated tip crosses the map where the real one did",
    )
    p.add_argument(
        "--plot", metavar="PNG", default=None, help="save a sim-vs-real figure"
    )
    p.add_argument(
        "--out",
        metavar="FILE",
        default=None,
        help="save the simulated log (.parquet or .csv)",
    )
    # compare-real needs the measured map: no run without the data.
    add_data_dir_option(p, without=None, bags=True)
    add_json_option(p)
    p.set_defaults(handler=run_compare_real)

    s = subparsers.add_parser(
        "scan",
        help="simulate a scenario YAML (diagrams/*.yaml) and print its scan metrics",
        description=SCAN_DESCRIPTION,
    )
    s.add_argument(
        "scenario",
        metavar="SCENARIO.yaml",
        help="a scenario file: diagrams/*.yaml, a campaign's scenarios/run_*.yaml, "
        "a reproduce run's logs/*.scenario.yaml, or the name of a shipped one "
        "(nominal_vs_vf_synthetic for diagrams/nominal_vs_vf_synthetic.yaml)",
    )
    s.add_argument(
        "--duration",
        metavar="S",
        default=None,
        help="simulated time, s (default: the scenario's duration_s, else its "
        f"trajectory's end + 1 s; at most {MAX_EXTRA_DURATION_S:g} s beyond that)",
    )
    s.add_argument(
        "--force-limit",
        metavar="N",
        default=None,
        help="the force limit of time_above_limit_s, N (default: the campaign's "
        "force_limit_N when SCENARIO.yaml is one of a campaign's runs, else "
        "15, the campaigns' default)",
    )
    s.add_argument(
        "--out", metavar="FILE", default=None, help="save the log (.parquet or .csv)"
    )
    s.add_argument(
        "--bag",
        metavar="DIR",
        default=None,
        help="also write the log as a ROS 2 bag folder in the real rig's layout "
        "(31 columns on /adaptive_stiffness_data for VS-CF/VS-VF, 9 on "
        "/data_control for CS/CF; vic_drake.experiments.rig_log)",
    )
    add_data_dir_option(s)
    add_json_option(s)
    s.set_defaults(handler=run_scan_command)


#: Suffixes of a saved log (--out) and of a saved figure (--plot).
LOG_SUFFIXES = (".parquet", ".csv")


def _save_log(df, out: str) -> Path:
    """Writes a scan DataFrame as .parquet or .csv; returns the path."""
    path = check_output_file(out, "--out", LOG_SUFFIXES)
    if path.suffix == ".csv":
        df.to_csv(path, index=False)
    else:
        df.to_parquet(path, index=False)
    return path


def run_compare_real(args: argparse.Namespace) -> int:
    from vic_drake.analysis.real_comparison import COMPARE_REAL_KEYS
    from vic_drake.experiments.compare_real import compare_real

    stiffness = (
        None if args.stiffness is None else _positive(args.stiffness, "--stiffness")
    )
    force = None if args.force is None else _positive(args.force, "--force")
    r = None if args.r_weight is None else _positive(args.r_weight, "--R")
    duration = None if args.duration is None else _positive(args.duration, "--duration")
    offset = (
        None if args.surface_offset is None else _surface_offset(args.surface_offset)
    )
    passes = "auto" if args.lateral_passes is None else _count(args.lateral_passes)
    relaxation = None if args.relaxation is None else parse_relaxation(args.relaxation)
    # Output paths are checked before simulating: a bad one fails now.
    if args.out:
        check_output_file(args.out, "--out", LOG_SUFFIXES)
    if args.plot:
        check_output_file(args.plot, "--plot", PLOT_SUFFIXES)
    bag = bag_path(
        args,
        args.bag_dir,
        expected="a ROS 2 bag folder (metadata.yaml + .db3) of a scan: 31 columns "
        "(VS controller) or 9 columns (CS/CF)",
    )
    progress = Progress(True)
    out, sim, real = compare_real(
        bag,
        controller=args.controller,
        stiffness_N_per_m=stiffness,
        force_N=force,
        r_weight=r,
        data_dir=args.data_dir,
        duration_s=duration,
        tissue_law=args.tissue_law,
        relaxation=relaxation,
        surface_offset=offset,
        lateral_passes=passes,
        progress=progress,
        return_frames=True,
    )
    if args.out:
        out["sim_log"] = str(_save_log(sim, args.out))
    if args.plot:
        from vic_drake.reproduce.plots.scans import plot_comparison

        plot_comparison(sim, real, title=Path(args.bag_dir).name, save_path=args.plot)
    ordered = {k: out.get(k) for k in COMPARE_REAL_KEYS}
    ordered.update({k: v for k, v in out.items() if k not in ordered})
    emit(ordered, args.json, compare_real_summary(Path(args.bag_dir).name, ordered))
    return 0


def _mm(value, sign: bool = False) -> str:
    return "?" if value is None else f"{value:{'+' if sign else ''}.2f} mm"


def compare_real_summary(name: str, out: dict) -> str:
    """compare-real's result in words: the scores, then what the simulation
    assumed of the phantom (at rest or moved, where its surface is) and the
    contact loss and peaks it is judged on."""
    kz = "n/a" if out.get("kz_corr") is None else f"{out['kz_corr']:.3f}"
    lines = [
        f"{name} ({out['controller']}, {out['duration_s']:.1f} s, {out['rtf']:.2f}x real time): "
        f"force RMSE {out['force_rmse_N']:.3f} N, peak error "
        f"{out['force_peak_err_N']:.3f} N, z RMSE {out['z_rmse_mm']:.2f} mm, K_z corr {kz}"
    ]
    share = out.get("phantom_motion_significance")
    sigma = out.get("phantom_motion_sigma_median_mm")
    beyond = "" if share is None else f"{share:.0%} of the samples beyond 3 sigma"
    if out.get("phantom_motion_replayed"):
        lines.append(
            f"  phantom: moved, up to {_mm(out.get('phantom_motion_max_mm'))} "
            f"({beyond}, sigma {_mm(sigma)}; against the "
            f"{out.get('phantom_motion_reference')}); its motion is replayed"
        )
    else:
        lines.append(
            f"  phantom: at rest (its estimated motion is noise: {beyond}, "
            f"sigma {_mm(sigma)})"
        )
    source = out.get("surface_offset_source")
    if source == "placement":
        lines.append(
            "  surface: the map placed by the log's in-contact surface, offset "
            f"{_mm(out.get('surface_placement_offset_mm'), True)}, tilt "
            f"{out.get('surface_placement_slope_mm_per_m', 0.0):+.1f} mm/m along the track"
        )
    else:
        lines.append(
            f"  surface: the map offset by {_mm(out.get('surface_offset_mm'), True)} "
            f"({source})"
        )
    sim_loss = out.get("contact_loss_total_sim_s") or 0.0
    real_loss = out.get("contact_loss_total_real_s") or 0.0
    if sim_loss or real_loss:
        lines.append(
            f"  contact lost: {sim_loss:.2f} s simulated, {real_loss:.2f} s real, "
            f"{out.get('contact_loss_overlap_s') or 0.0:.2f} s of it at the same time"
        )
    else:
        lines.append("  contact lost: never, in either")
    lines.append(
        f"  peak force: {out['force_peak_sim_N']:.2f} N simulated, "
        f"{out['force_peak_real_N']:.2f} N real"
    )
    return "\n".join(lines)


def run_scan_command(args: argparse.Namespace) -> int:
    from vic_drake.experiments import run_scan
    from vic_drake.scenario import load_scenario, save_scenario

    progress = Progress(True)
    path = scenario_path(args.scenario, progress)
    scenario = load_scenario(path)
    duration = None if args.duration is None else _positive(args.duration, "--duration")
    if duration is not None:
        check_scan_duration(scenario, duration)
    simulated = scenario.total_duration_s if duration is None else duration
    for late in scenario.variations.sensor_faults.starting_after(simulated):
        progress(
            f"note: variations.sensor_faults.{late} is not before the run's end "
            f"({simulated:g} s): this run has no such fault"
        )
    force_limit = (
        None
        if args.force_limit is None
        else _positive(args.force_limit, "--force-limit")
    )
    if args.out:  # Checked before simulating, as --bag below.
        check_output_file(args.out, "--out", LOG_SUFFIXES)
    if args.bag:
        # Checked before simulating: a bad path fails now, not after the run.
        from vic_drake.experiments.rig_log import check_bag_scenario
        from vic_drake.realdata_write import check_bag_target

        check_bag_target(args.bag, option="--bag")
        check_bag_scenario(scenario)
        if scenario.stiffness_source == "online":
            progress(
                "note: with stiffness_source online the bag's kappa and lambda "
                "columns hold the controller's online estimates, not a map: "
                "estimate-online on this bag compares an estimator with them"
            )
    result = run_scan(
        scenario, duration_s=duration, data_dir=args.data_dir, progress=progress
    )
    out = scan_metrics_dict(scenario, result, path, force_limit)
    if args.out:
        log = _save_log(result.df, args.out)
        save_scenario(scenario, log.with_suffix(".scenario.yaml"))
        out["log"] = str(log)
    if args.bag:
        from vic_drake.experiments.rig_log import write_scan_bag

        out["bag"] = str(write_scan_bag(result, args.bag))
    emit(out, args.json, scan_human_summary(out, scenario))
    return 0
