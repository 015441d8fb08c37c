"""Stage ``online``: the online tissue estimators (RLS, EKF) replayed tick by tick.

With the paper's data: over its palpation logs (reference: the offline fit
of the whole log) and its VS scan logs (reference: the map values the
controller logged), as ``vic-drake estimate-online`` does. On every run:
over this run's simulated palpations (the ``offline_sim`` stage's bags,
against their own whole-log fit) and its simulated VS-VF scan, against the
phantom's true kappa under the probe. A table of the scores and a figure
of kappa-hat.
"""

from __future__ import annotations

import numpy as np

from vic_drake.estimation.online import (
    ONLINE_METHODS,
    OnlineEstimatorParams,
    run_online,
)
from vic_drake.reproduce.context import RunContext, StageSkipped
from vic_drake.reproduce.report import ReportTable
from vic_drake.tissue import load_phantom

#: The real logs replayed (folders under the data folder).
ONLINE_REAL_LOGS = (
    "palpation/test_soft_1hz",
    "palpation/test_soft_2hz",
    "palpation/test_soft_25hz",
    "experiments/test_tracking5",
    "experiments/test_nardi_matForce_lowR",
)


def _row(name: str, method: str, summary: dict) -> list:
    def fmt(v, spec):
        return "-" if v is None or not np.isfinite(v) else format(v, spec)

    return [
        name,
        method,
        fmt(summary["kappa_rel_err_median"], ".3f"),
        fmt(summary["kappa_corr"], ".2f"),
        fmt(summary["lambda_rel_err_median"], ".2f"),
        fmt(summary["convergence_s"], ".2f"),
        fmt(summary["tick_us_p99"], ".0f"),
    ]


def replay_simulated_scan(df, phantom, params: OnlineEstimatorParams) -> tuple:
    """(trace, kappa_true, summary) of one estimator over a simulated scan.

    Scored as ``vic-drake estimate-online`` scores a log
    (:func:`~vic_drake.experiments.online_replay.score_online`). The
    estimator sees what the real one would: tip height and rate, the
    sensor's force and the surface of the phantom at rest under the probe
    (the map, not the simulation's lifted truth); it is scored against the
    true kappa under the probe.
    """
    t, x, y, z = (df[c].to_numpy(float) for c in ("t_s", "x_m", "y_m", "z_m"))
    tissue = phantom.sample(x, y)
    trace = run_online(
        t,
        z,
        np.gradient(z, t),
        -df["force_sensor_z_N"].to_numpy(float),
        np.asarray(tissue.surface_z_m, float),
        params,
    )
    # Function-local: the replay module reads bags (pandas, rosbags).
    from vic_drake.experiments.online_replay import score_online

    kappa = np.asarray(tissue.kappa, float)
    lam = np.asarray(tissue.lam, float)
    summary = score_online("scan", trace, kappa, lam, 0.0, params).summary
    return trace, kappa, summary


def stage_online(ctx: RunContext) -> dict:
    """Scores of both estimators on the real logs (if any) and the simulated scan."""
    # Function-local: the replay reads bags (pandas, rosbags).
    from vic_drake.experiments.online_replay import replay_online

    rows, results, traces = [], {}, {}
    if ctx.data_dir is not None:
        for name in ONLINE_REAL_LOGS:
            path = ctx.data_dir / name
            if not path.exists():
                ctx.progress(f"  real log {name} missing; skipped")
                continue
            for method in ONLINE_METHODS:
                replay = replay_online(
                    path, params=OnlineEstimatorParams(method=method)
                )
                results[(name, method)] = replay.summary
                rows.append(_row(name, method, replay.summary))
                traces[(name, method)] = replay
    # This run's simulated palpations, as their bags (what estimate-online reads).
    bags = (ctx.results.get("offline_sim") or {}).get("palpation_bags", {})
    for f, path in sorted(bags.items()):
        name = f"simulated palpation {f:g} Hz ({ctx.phantom_kind})"
        for method in ONLINE_METHODS:
            replay = replay_online(path, params=OnlineEstimatorParams(method=method))
            results[(name, method)] = replay.summary
            rows.append(_row(name, method, replay.summary))
    frames = (ctx.results.get("scans") or {}).get("frames", {})
    sim = frames.get("nominal", {}).get("vs-vf")
    sim_traces = {}
    if sim is not None:
        phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
        for method in ONLINE_METHODS:
            trace, kappa, summary = replay_simulated_scan(
                sim, phantom, OnlineEstimatorParams(method=method)
            )
            name = f"simulated VS-VF scan ({ctx.phantom_kind})"
            results[(name, method)] = summary
            rows.append(_row(name, method, summary))
            sim_traces[method] = (trace, kappa)
    if not rows:
        raise StageSkipped(
            "no real logs and no simulated palpation or VS-VF scan (run the "
            "offline_sim or scans stage too)"
        )
    ctx.tables.append(
        ReportTable(
            "Online estimation: RLS and EKF replayed tick by tick",
            [
                "log",
                "method",
                "kappa median rel. error",
                "kappa corr.",
                "lambda median rel. error",
                "convergence [s]",
                "tick p99 [us]",
            ],
            rows,
            "Palpations (real, and this run's simulated ones) against the offline "
            "fit of the whole log; real VS scans "
            "against the map values the controller logged; the simulated scan "
            "against the phantom's true kappa under the probe. Convergence: from "
            "first contact until kappa-hat stays within 10 % ('-': never). The "
            "tick is the pure function's wall time on this machine.",
        )
    )
    _figure(ctx, traces, sim_traces)
    return {"summaries": {f"{k[0]} [{k[1]}]": v for k, v in results.items()}}


def _figure(ctx: RunContext, traces: dict, sim_traces: dict) -> None:
    # Function-local: matplotlib (heavy).
    import matplotlib.pyplot as plt

    panels = []
    palp = traces.get(("palpation/test_soft_2hz", "rls"))
    if palp is not None:
        panels.append(("palpation/test_soft_2hz, RLS", palp.trace, palp.kappa_ref))
    scan = traces.get(("experiments/test_tracking5", "ekf"))
    if scan is not None:
        panels.append(("experiments/test_tracking5, EKF", scan.trace, scan.kappa_ref))
    if "ekf" in sim_traces:
        trace, kappa = sim_traces["ekf"]
        panels.append((f"simulated VS-VF scan ({ctx.phantom_kind}), EKF", trace, kappa))
    if not panels:
        return
    fig, axes = plt.subplots(
        len(panels), 1, figsize=(8, 2.6 * len(panels)), squeeze=False
    )
    for ax, (title, trace, ref) in zip(axes[:, 0], panels):
        contact = trace.in_contact
        t = trace.t_s - trace.t_s[0]
        kappa = np.where(contact, trace.kappa, np.nan)
        ref = np.broadcast_to(np.asarray(ref, float), t.shape)
        ax.fill_between(t, 0.9 * ref, 1.1 * ref, color="0.85", label="reference +-10 %")
        ax.plot(t, ref, color="k", lw=1, label="reference")
        ax.plot(t, kappa, color="C0", lw=1, label="kappa-hat (in contact)")
        ax.set_title(title, fontsize=10)
        ax.set_ylabel("kappa [N/m^beta]")
    axes[-1, 0].set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    ctx.add_figure(
        "Online estimation: kappa-hat over time",
        "The online estimate of kappa (in contact) against its reference, with a "
        "+-10 % band.",
        fig,
        "online_estimation.png",
    )
