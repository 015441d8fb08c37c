"""Stage ``compare_real``: each real scan re-run in simulation and compared
with its log (full mode only)."""

from __future__ import annotations

import os

from vic_drake.analysis.real_comparison import COMPARE_REAL_KEYS
from vic_drake.reproduce.context import RunContext, StageSkipped
from vic_drake.reproduce.report import ReportTable
from vic_drake.reproduce.stages.real_scans import REAL_SCAN_LOGS


def _compare_real_job(args):
    """Worker: one real experiment re-run in simulation (module-level: a Dask
    worker imports it). It reads the log and the map from the data folder's
    path, which a worker of an external cluster must see too."""
    # Function-local: pydrake (heavy).
    from vic_drake.experiments.compare_real import compare_real

    bag, data_dir, relaxation = args
    return compare_real(
        bag, data_dir=data_dir, relaxation=relaxation, return_frames=True
    )


def stage_compare_real(ctx: RunContext) -> dict:
    """Each real scan re-run in simulation on the measured map, compared with its log.

    :func:`vic_drake.experiments.compare_real` (logged target, controller
    settings identified from the log, the phantom's motion replayed where the
    log shows it). Full mode only.
    """
    if ctx.data_dir is None:
        raise StageSkipped("no real data (pass --data-dir or set VIC_DRAKE_DATA)")
    if ctx.options.quick:
        raise StageSkipped("full mode only (six more simulations of 20-26 s)")
    names = sorted(set(REAL_SCAN_LOGS.values()))
    # Function-local: distributed (heavy).
    from vic_drake.experiments.dask_cluster import map_on_cluster

    opts = ctx.options
    workers = opts.workers or max(1, min(len(names), os.cpu_count() or 1))

    def on_done(i, result, _done) -> None:
        ctx.progress(
            f"  {names[i]}: force RMSE {result[0]['force_rmse_N']:.2f} N, "
            f"z RMSE {result[0]['z_rmse_mm']:.1f} mm"
        )

    results = map_on_cluster(
        _compare_real_job,
        [
            (ctx.data_dir / "experiments" / name, ctx.data_dir, opts.relaxation)
            for name in names
        ],
        workers,
        opts.scheduler,
        name="reproduce-compare-real",
        describe=lambda i: f"the re-run of {names[i]}",
        on_done=on_done,
    )
    out = dict(zip(names, results, strict=True))
    ctx.tables.append(
        ReportTable(
            "Real experiments re-run in simulation (measured map)",
            [
                "log",
                *COMPARE_REAL_KEYS,
                "contact loss sim / real / both [s]",
                "phantom motion max [mm]",
            ],
            [
                [
                    name,
                    *(res[0].get(k) for k in COMPARE_REAL_KEYS),
                    " / ".join(
                        f"{res[0][k]:.2f}"
                        for k in (
                            "contact_loss_total_sim_s",
                            "contact_loss_total_real_s",
                            "contact_loss_overlap_s",
                        )
                    ),
                    f"{res[0]['phantom_motion_max_mm']:.1f}"
                    + ("" if res[0]["phantom_motion_replayed"] else " (not replayed)"),
                ]
                for name, res in out.items()
            ],
            "vic_drake.experiments.compare_real: each real scan's target, the controller "
            "and settings identified from its signals, and the phantom's motion estimated "
            "from the log (replayed where significant), simulated and compared with the "
            "log after time alignment. kz_corr: correlation of simulated and logged K_z.",
        )
    )
    # Function-local: matplotlib (heavy).
    from vic_drake.reproduce.plots.scans import plot_comparison

    for name in ("test_nardi_matForce_lowR", "test_compliance_control400_dist"):
        if name in out:
            _, sim_df, real_df = out[name]
            ctx.add_figure(
                f"Real vs simulated: {name}",
                "The real log and its simulation on the measured map.",
                plot_comparison(sim_df, real_df, title=name),
                f"compare_real_{name}.png",
            )
    return {name: res[0] for name, res in out.items()}
