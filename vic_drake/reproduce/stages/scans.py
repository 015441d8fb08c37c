"""Stage ``scans``: the paper's scans in simulation, their logs and Fig. 6-7.

The four controllers (CS, CF, VS-CF, VS-VF) nominal, and VS-VF, CS, CF with
the phantom lifted and lowered; every log written as parquet with its
scenario YAML beside it and as a ROS 2 bag in the real rig's layout
(``logs/<name>_bag/``).
"""

from __future__ import annotations

import os
import time
from dataclasses import replace

from vic_drake.analysis import claims as claims_mod
from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTROLLERS, DISTURBANCE_CONTROLLERS
from vic_drake.reproduce.context import RunContext
from vic_drake.reproduce.report import ReportTable

#: Quick mode: the target starts QUICK_APPROACH_Z_M high (just above the
#: surface at the start; see docs/decisions.md, "Quick mode") and scans
#: QUICK_SCAN_M along -x.
QUICK_APPROACH_Z_M = 0.11
QUICK_SCAN_M = 0.05


def scan_scenario(
    controller: str,
    *,
    disturbed: bool,
    phantom_kind: str,
    quick: bool,
    relaxation=None,
):
    """The scenario of one of the paper's scans (nominal or disturbed).

    ``diagrams/nominal_<controller>_synthetic.yaml`` (the real rig's scan and
    controller settings; :func:`vic_drake.experiments.load_diagram`) on the
    requested phantom, with :func:`vic_drake.experiments.disturbance_lifts`
    as the disturbance.
    Quick mode shortens the approach and the scan (QUICK_* constants) and
    has one disturbance event instead of two. ``relaxation`` (a
    RelaxationParams) replaces the relaxing tissue's default branches.
    """
    # Function-local: the experiments and the scenario pull in pydrake (heavy).
    from vic_drake.experiments import disturbance_lifts, load_diagram, scan_start_s
    from vic_drake.scenario import DisturbanceConfig

    if controller not in CONTROLLERS:
        raise VicDrakeError(
            f"controller must be one of {list(CONTROLLERS)}; got {controller!r}"
        )
    base = load_diagram(f"nominal_{controller.replace('-', '_')}_synthetic")
    traj = base.trajectory
    if quick:
        traj = replace(
            traj, approach_z_m=QUICK_APPROACH_Z_M, end_x_m=traj.start_x_m - QUICK_SCAN_M
        )
    disturbance = DisturbanceConfig()
    if disturbed:
        disturbance = DisturbanceConfig(
            lifts=disturbance_lifts(scan_start_s(traj), events=1 if quick else 2)
        )
    cond = "disturbance" if disturbed else "nominal"
    station = base.station
    if relaxation is not None:
        station = station.with_relaxation(relaxation)
    return replace(
        base,
        name=f"{cond}_{controller.replace('-', '_')}_{phantom_kind}",
        description=f"{controller.upper()} {cond} scan on the {phantom_kind} phantom "
        f"({'quick' if quick else 'full'} mode)",
        phantom=replace(base.phantom, kind=phantom_kind),
        trajectory=traj,
        disturbance=disturbance,
        station=station,
    )


def scan_limits(scenario) -> claims_mod.ScanLimits:
    """K_min, T_min, P_max, eps_d of a scenario's controller."""
    return claims_mod.ScanLimits.from_controller(scenario.controller)


def _run_scan_job(args):
    """Worker: one scan on the phantom it is given (module-level: a Dask
    worker imports it; it needs no data folder)."""
    # Function-local: pydrake (heavy).
    from vic_drake.experiments import run_scan

    scenario, phantom = args
    return run_scan(scenario, phantom=phantom)


def stage_scans(ctx: RunContext) -> dict:
    """The four controllers nominal, VS-VF/CS/CF disturbed; logs; Fig. 6-7.

    The scans run on Dask: ``ctx.options.workers`` local workers (default
    one per core) or the cluster of ``ctx.options.scheduler``.
    """
    # Function-local: pydrake and distributed (heavy).
    from vic_drake.experiments import load_scenario_phantom
    from vic_drake.experiments.dask_cluster import map_on_cluster
    from vic_drake.experiments.rig_log import check_bag_scenario, write_scan_bag
    from vic_drake.scenario import save_scenario

    runs = [("nominal", c) for c in CONTROLLERS] + [
        ("disturbance", c) for c in DISTURBANCE_CONTROLLERS
    ]
    scenarios = {
        key: scan_scenario(
            key[1],
            disturbed=key[0] == "disturbance",
            phantom_kind=ctx.phantom_kind,
            quick=ctx.options.quick,
            relaxation=ctx.options.relaxation,
        )
        for key in runs
    }
    for scenario in scenarios.values():  # Before simulating: each log can be a bag.
        check_bag_scenario(scenario)
    logs = ctx.out_dir / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    opts = ctx.options
    workers = opts.workers or os.cpu_count() or 1
    where = (
        f"on the Dask scheduler {opts.scheduler}"
        if opts.scheduler
        else f"on {workers} local Dask worker(s)"
    )
    ctx.progress(f"  {len(runs)} scans {where}")
    phantoms = {}  # Loaded once here and sent with each scan: no data on a worker.

    def phantom_of(scenario):
        key = (scenario.phantom.kind, scenario.phantom.lookup)
        if key not in phantoms:
            phantoms[key] = load_scenario_phantom(scenario, data_dir=ctx.data_dir)
        return phantoms[key]

    jobs = [(scenarios[k], phantom_of(scenarios[k])) for k in runs]

    def on_done(i, result, done) -> None:
        _report_scan(ctx, scenarios[runs[i]], result, done, len(runs))

    t0 = time.perf_counter()
    simulated = map_on_cluster(
        _run_scan_job,
        jobs,
        workers,
        opts.scheduler,
        name="reproduce-scan",
        describe=lambda i: f"the scan {scenarios[runs[i]].name}",
        on_done=on_done,
    )
    results = dict(zip(runs, simulated, strict=True))
    ctx.progress(f"  scans done in {time.perf_counter() - t0:.1f} s")
    frames: dict = {"nominal": {}, "disturbance": {}}
    metrics: dict = {"nominal": {}, "disturbance": {}}
    timing = []
    limits = None
    for key in runs:
        cond, ctrl = key
        scenario, result = scenarios[key], results[key]
        df = result.df
        df.to_parquet(logs / f"{scenario.name}.parquet", index=False)
        save_scenario(scenario, logs / f"{scenario.name}.yaml")
        # The same log as the real rig's ROS 2 bag (rig_log.write_scan_bag).
        write_scan_bag(result, logs / f"{scenario.name}_bag")
        lim = scan_limits(scenario)
        limits = limits or lim
        frames[cond][ctrl] = df
        metrics[cond][ctrl] = claims_mod.scan_metrics(df, limits=lim)
        timing.append([scenario.name, result.sim_s, result.wall_s, result.rtf])
    _scan_figures(ctx, frames)
    ctx.tables.append(
        ReportTable(
            "Simulated scans: timing",
            ["run", "simulated [s]", "wall [s]", "real-time factor"],
            timing,
            f"The scans {where}.",
        )
    )
    return {
        "frames": frames,
        "metrics": metrics,
        "limits": limits,
        "timing": timing,
        "scenarios": scenarios,
    }


def _report_scan(ctx, scenario, result, done: int, total: int) -> None:
    ctx.progress(
        f"  scan {done}/{total} {scenario.name}: {result.sim_s:.1f} s simulated "
        f"in {result.wall_s:.1f} s (real-time factor {result.rtf:.2f})"
    )


def _scan_figures(ctx: RunContext, frames: dict) -> None:
    # Function-local: matplotlib (heavy).
    from vic_drake.reproduce.plots.scans import plot_fig6, plot_fig7

    real = (ctx.results.get("real_scans") or {}).get("frames", {})
    overlay = (
        " (grey: the paper's real logs)"
        if real.get("nominal")
        else "; no real logs in this run"
    )
    nominal = {
        k: frames["nominal"][k] for k in ("vs-cf", "vs-vf") if k in frames["nominal"]
    }
    if nominal:
        ctx.add_figure(
            "Fig. 6: VS-CF and VS-VF, nominal",
            f"Simulated scans on the {ctx.phantom_kind} phantom{overlay}: force with "
            "F_ref and F_min, K_z, penetration, tank energy.",
            plot_fig6(nominal, real.get("nominal")),
            "fig6_nominal.png",
        )
    base = {k: frames["nominal"][k] for k in ("cs", "cf") if k in frames["nominal"]}
    if base:
        ctx.add_figure(
            "CS and CF, nominal (not in the paper's Fig. 6)",
            f"The baselines' nominal scans on the {ctx.phantom_kind} "
            f"phantom{overlay}: force and penetration. Their K_z and tank are "
            "constant (CS: fixed stiffness; CF: no tank) and not drawn.",
            plot_fig6(base, real.get("nominal")),
            "fig6_baselines.png",
        )
    dist = {
        k: frames["disturbance"][k]
        for k in DISTURBANCE_CONTROLLERS
        if k in frames["disturbance"]
    }
    if dist:
        ctx.add_figure(
            "Fig. 7: VS-VF, CS, CF with the phantom lifted",
            "Phantom lifted and dropped during the scan: force, tip height with "
            "the moving surface, K_z"
            + (
                ". Last row: the paper's _dist logs of CS and CF, on their own "
                "time axis (their phantom was moved by hand, not by the "
                "simulated lift; vic-drake compare-real replays a log's own "
                "motion)."
                if real.get("disturbance")
                else "; no real logs in this run."
            ),
            plot_fig7(dist, real.get("disturbance")),
            "fig7_disturbance.png",
        )
