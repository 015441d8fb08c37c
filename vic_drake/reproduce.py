"""The paper, end to end: offline estimation, scans, disturbance, claims, report.

The pipeline is a list of stages. Each stage is a function
``stage(ctx) -> value`` that reads the results of earlier stages from the
:class:`RunContext` and returns its own; :func:`run_pipeline` runs them in
order, times each, shows progress, and records a stage that fails (its error
message, the traceback in ``logs/errors.txt``) instead of stopping: the claims
that need a failed stage are then reported as not evaluated, with the reason,
and fail.

Stages (see :data:`STAGES`):

- ``offline_real``: Table I, beta sweep, residual vs palpation time and load
  test on the paper's palpation logs (when the data is there).
- ``offline_sim``: the same fits on palpations simulated on the phantom.
- ``map``: palpation campaign on a grid, surface fit and GP maps of kappa and
  lambda; rib detection on the estimated and on the measured map.
- ``scans``: the four controllers (CS, CF, VS-CF, VS-VF) nominal, and VS-VF,
  CS, CF with the phantom lifted and lowered; every log written as parquet
  with its scenario YAML beside it.
- ``real_scans``: the paper's scan logs reduced to the same metrics.
- ``compare_real``: (full mode) each real scan re-run in simulation on the
  measured map and compared with its log.
- ``claims``: C1-C7 (:mod:`vic_drake.claims`) -> ``claims.json``.
- ``replay``: a Meshcat recording of one scan -> ``replay.html``.
- ``report``: ``report.html`` (figures, tables, claims, metadata).

:func:`reproduce` is the library entry point; ``vic-drake reproduce`` is a
thin wrapper.
"""

from __future__ import annotations

import json
import os
import platform
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from vic_drake import claims as claims_mod
from vic_drake.errors import VicDrakeError
from vic_drake.paths import has_data, resolve_data_dir
from vic_drake.realdata import read_bag, read_phantom_map

#: Controllers of the paper, in the order of its figures.
CONTROLLERS = ("cs", "cf", "vs-cf", "vs-vf")
#: Controllers run under the disturbance (the paper's Fig. 7).
DISTURBANCE_CONTROLLERS = ("vs-vf", "cs", "cf")

#: The paper's scan logs: {(condition, controller): folder under experiments/}.
REAL_SCAN_LOGS = {
    ("nominal", "cs"): "test_compliance_control400",
    ("nominal", "cf"): "test_force_control",
    ("nominal", "vs-cf"): "test_tracking5",
    ("nominal", "vs-vf"): "test_nardi_matForce_lowR",
    ("disturbance", "cs"): "test_compliance_control400_dist",
    ("disturbance", "cf"): "test_force_control_dist",
}
#: CF's force reference on the real rig (not logged; data/README.md: 7 N).
REAL_CF_REFERENCE_N = 7.0
#: The real controller's settings (data/README.md).
REAL_LIMITS = claims_mod.ScanLimits(
    k_min_z_N_per_m=100.0, tank_min_J=0.4, power_max_W=0.1, eps_d_m=0.008
)


class StageSkipped(VicDrakeError):
    """A stage cannot run here (missing data or a missing part of vic_drake)."""


@dataclass
class ReproduceOptions:
    """Options of a reproduction run.

    Attributes:
        out_dir: folder for every output (created).
        data_dir: the paper's measurements (None: the default lookup).
        quick: shorter scans and a coarser map (< 5 min on 2 cores).
        phantom: "auto" (measured map when the data is there, else synthetic),
            "measured" or "synthetic".
        stages: names of the stages to run (None: all).
        progress: called with one line of progress text.
    """

    out_dir: Path
    data_dir: Path | None = None
    quick: bool = False
    phantom: str = "auto"
    stages: tuple[str, ...] | None = None
    progress: Callable[[str], None] = lambda message: None

    def __post_init__(self):
        self.out_dir = Path(self.out_dir)
        if self.phantom not in ("auto", "measured", "synthetic"):
            raise VicDrakeError(
                f"phantom must be 'auto', 'measured' or 'synthetic', got {self.phantom!r}"
            )
        if self.data_dir is not None and not has_data(self.data_dir):
            raise VicDrakeError(
                f"--data-dir {str(self.data_dir)!r} does not hold the paper's data; expected "
                "phantom_map/, experiments/, palpation/ and loadcycle/ in it (omit the "
                "option to run on the synthetic phantom)"
            )
        if self.phantom == "measured" and not has_data(self.data_dir):
            raise VicDrakeError(
                f"--phantom measured needs the paper's phantom map; none found at "
                f"{str(resolve_data_dir(self.data_dir))!r} (pass --data-dir DIR or set "
                "VIC_DRAKE_DATA)"
            )
        if self.stages is not None:
            unknown = [s for s in self.stages if s not in STAGE_NAMES]
            if unknown:
                raise VicDrakeError(
                    f"unknown stage(s) {unknown}; allowed: {', '.join(STAGE_NAMES)}"
                )


@dataclass
class StageRecord:
    """How a stage went."""

    name: str
    ok: bool
    wall_s: float
    error: str | None = None
    skipped: bool = False  # Not run here by design (no data, quick mode).

    @property
    def status(self) -> str:
        return "ok" if self.ok else ("skipped" if self.skipped else "failed")

    def as_dict(self) -> dict:
        return {"name": self.name, "ok": self.ok, "status": self.status,
                "wall_s": round(self.wall_s, 2), "error": self.error}


@dataclass
class RunContext:
    """The options, the stage results so far and the run's bookkeeping."""

    options: ReproduceOptions
    results: dict[str, Any] = field(default_factory=dict)
    records: list[StageRecord] = field(default_factory=list)
    figures: list = field(default_factory=list)  # list[report.ReportFigure]
    tables: list = field(default_factory=list)  # list[report.ReportTable]

    @property
    def out_dir(self) -> Path:
        return self.options.out_dir

    @property
    def data_dir(self) -> Path | None:
        d = resolve_data_dir(self.options.data_dir)
        return d if has_data(d) else None

    @property
    def phantom_kind(self) -> str:
        if self.options.phantom != "auto":
            return self.options.phantom
        return "measured" if self.data_dir is not None else "synthetic"

    def progress(self, message: str) -> None:
        self.options.progress(message)

    def stage_error(self, name: str) -> str | None:
        for r in self.records:
            if r.name == name and not r.ok:
                return r.error
        if name not in self.results:
            return f"stage {name!r} did not run"
        return None

    def add_figure(self, title: str, caption: str, fig, filename: str) -> Path:
        """Saves a matplotlib figure under figures/ and adds it to the report."""
        from vic_drake.report import ReportFigure

        path = self.out_dir / "figures" / filename
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=110, bbox_inches="tight")
        import matplotlib.pyplot as plt

        plt.close(fig)
        self.figures.append(ReportFigure(title, caption, path))
        return path


def _write_log(ctx: RunContext, name: str, df: pd.DataFrame, config: dict) -> None:
    """logs/<name>.parquet and, beside it, logs/<name>.yaml with its configuration."""
    import dataclasses

    import yaml

    def plain(v):
        if dataclasses.is_dataclass(v):
            return plain(dataclasses.asdict(v))
        if isinstance(v, dict):
            return {str(k): plain(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [plain(x) for x in v]
        if isinstance(v, (np.floating, np.integer)):
            return v.item()
        return v

    logs = ctx.out_dir / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    df.to_parquet(logs / f"{name}.parquet", index=False)
    (logs / f"{name}.yaml").write_text(yaml.safe_dump(plain(config), sort_keys=False),
                                       encoding="utf-8")


# --- Real scan logs -----------------------------------------------------------


def real_scan_frame(df: pd.DataFrame, *, controller: str | None = None) -> pd.DataFrame:
    """A real scan log in the canonical scan columns (those it has).

    Args:
        df: :func:`vic_drake.realdata.read_bag` output of a 9-column (CS/CF)
            or 31-column (variable impedance) log.
        controller: for the 9-column layout, "cf" adds the 7 N reference the
            rig used (not logged); "cs" has no force reference.

    Returns:
        :func:`vic_drake.metrics.real_to_canonical` without the columns the
        log does not hold (9-column: pose, z target, sensor z force,
        contact; 31-column: also the controller's signals).

    Raises:
        VicDrakeError: a log that is not a scan log.
    """
    from vic_drake.metrics import real_to_canonical

    out = real_to_canonical(df)
    out = out[[c for c in out.columns if out[c].notna().any()]]
    if df.attrs.get("layout") == "scan" and controller == "cf":
        out["force_ref_z_N"] = -REAL_CF_REFERENCE_N
    return out


def stage_real_scans(ctx: RunContext) -> dict:
    """The paper's scan logs -> canonical frames and claim metrics; ribs in the
    paper's measured kappa map (C3 "real")."""
    if ctx.data_dir is None:
        raise StageSkipped("no real data (pass --data-dir or set VIC_DRAKE_DATA)")
    frames: dict = {"nominal": {}, "disturbance": {}}
    metrics: dict = {"nominal": {}, "disturbance": {}}
    for (cond, ctrl), folder in REAL_SCAN_LOGS.items():
        path = ctx.data_dir / "experiments" / folder
        if not path.exists():
            ctx.progress(f"  real log {folder} missing; skipped")
            continue
        df = real_scan_frame(read_bag(path), controller=ctrl)
        frames[cond][ctrl] = df
        metrics[cond][ctrl] = claims_mod.scan_metrics(df, limits=REAL_LIMITS)
    m = read_phantom_map(ctx.data_dir / "phantom_map")
    ribs = claims_mod.rib_prominences(m.x_m, m.y_m, m.kappa)
    return {"frames": frames, "metrics": metrics, "ribs": ribs}


# --- Offline estimation -------------------------------------------------------


#: The paper's palpation logs (Table I, Fig. 3) and the load test (Fig. 2).
REAL_PALPATION_LOGS = ("test_soft_1hz", "test_soft_2hz", "test_soft_25hz")
REAL_LOAD_LOG = "test_soft_1"
#: Simulated palpations: (frequency Hz) per log, and where (x, y) on the phantom.
SIM_PALPATION_FREQUENCIES_HZ = (1.0, 2.0, 2.5)
SIM_PALPATION_POINT_M = (-0.05, -0.36)
TABLE_I_BETAS = (1.1, 1.35, 1.5)


def _offline_fits(ctx: RunContext, logs: dict, label: str) -> dict:
    """Table I fits and residual-vs-time curves on {name: PalpationData}.

    Args:
        logs: {name: (PalpationData, lag_s or None)}.
        label: "real" or "sim" (figure names and titles).
    """
    from vic_drake.estimation.palpation import (
        compare_models,
        residual_vs_palpation_time,
        shift,
    )
    from vic_drake.plots.offline import (
        plot_beta_sweep,
        plot_residual_vs_time,
        plot_table_i,
    )

    comparisons, curves = {}, {}
    for name, (data, lag) in logs.items():
        ctx.progress(f"  {label}: fitting {name} ({data.duration_s:.0f} s)")
        comparisons[name] = compare_models(data, TABLE_I_BETAS, lag_s=lag)
        curves[name] = residual_vs_palpation_time(shift(data, comparisons[name].lag_s))
    kv = float(np.mean([c.kelvin_voigt.relative for c in comparisons.values()]))
    hc = {b: float(np.mean([c.hunt_crossley[b].relative for c in comparisons.values()]))
          for b in TABLE_I_BETAS}
    residuals = claims_mod.ModelResiduals(kv, hc)
    from vic_drake.report import ReportTable

    rows = []
    for name, c in comparisons.items():
        rows.append([name, c.lag_s * 1e3, c.kelvin_voigt.relative,
                     *(c.hunt_crossley[b].relative for b in TABLE_I_BETAS),
                     c.best_beta])
    rows.append(["mean", None, kv, *(hc[b] for b in TABLE_I_BETAS), None])
    rows.append(["paper", None, claims_mod.PAPER_TABLE_I["kelvin_voigt"],
                 *(claims_mod.PAPER_TABLE_I[f"hc_{b:g}"] for b in TABLE_I_BETAS), 1.35])
    ctx.tables.append(ReportTable(
        f"Table I ({label}): relative residual per model",
        ["log", "lag [ms]", "Kelvin-Voigt", *(f"HC beta={b:g}" for b in TABLE_I_BETAS),
         "best beta (sweep)"], rows,
        "Relative residual = RMS least-squares residual / RMS fitted force over the "
        "in-contact samples (vic_drake.estimation.palpation). The paper does not define "
        "its number: compare orderings."))
    ctx.add_figure(f"Table I ({label})", "Relative residual of Kelvin-Voigt and "
                   "Hunt-Crossley fits; black bars: the paper's values.",
                   plot_table_i(comparisons), f"table1_{label}.png")
    ctx.add_figure(f"Beta sweep ({label})", "Hunt-Crossley relative residual against "
                   "beta; dotted: best beta per log, dashed: the paper's 1.35.",
                   plot_beta_sweep({n: c.sweep for n, c in comparisons.items()}),
                   f"beta_sweep_{label}.png")
    ctx.add_figure(f"Fig. 3 ({label}): residual vs palpation time",
                   "Relative residual on the whole log of the parameters fitted on the "
                   "first T seconds, with an exponential fit (paper's Fig. 3).",
                   plot_residual_vs_time(curves), f"fig3_residual_vs_time_{label}.png")
    decay = {n: (c.window_s, c.relative) for n, c in curves.items()}
    return {"comparisons": comparisons, "curves": curves, "residuals": residuals,
            "decay": decay}


def stage_offline_real(ctx: RunContext) -> dict:
    """Table I, the beta sweep, residual vs time and the load test on real logs."""
    if ctx.data_dir is None:
        raise StageSkipped("no real data (pass --data-dir or set VIC_DRAKE_DATA)")
    from vic_drake.estimation.loadtest import load_test
    from vic_drake.estimation.palpation import PalpationData
    from vic_drake.plots.offline import plot_load_test

    logs = {}
    for name in REAL_PALPATION_LOGS:
        path = ctx.data_dir / "palpation" / name
        logs[name] = (PalpationData.from_frame(read_bag(path, expect="palpation")), None)
    out = _offline_fits(ctx, logs, "real")
    load = PalpationData.from_frame(
        read_bag(ctx.data_dir / "loadcycle" / REAL_LOAD_LOG, expect="palpation"))
    first = REAL_PALPATION_LOGS[0]
    lt = load_test(load, logs[first][0], lag_s=out["comparisons"][first].lag_s)
    ctx.add_figure("Fig. 2 (real): load test",
                   f"Load/unload test {REAL_LOAD_LOG} against Kelvin-Voigt and Hunt-Crossley "
                   f"fitted on {first} (paper's Fig. 2).", plot_load_test(lt),
                   "fig2_load_test_real.png")
    out["load_test"] = {"kelvin_voigt_rms_N": lt.kelvin_voigt_rms_N,
                        "hunt_crossley_rms_N": lt.hunt_crossley_rms_N}
    return out


def stage_offline_sim(ctx: RunContext) -> dict:
    """The same fits on palpations simulated on the phantom (Drake indenter bank).

    The simulated tissue is Hunt-Crossley with the phantom's beta (1.35), so
    C1 in simulation checks that the estimation pipeline (lag, noise, indenter
    mass, contact selection) recovers the model, not that tissue is HC.
    """
    from vic_drake.estimation.campaign import CampaignParams, simulate_palpations
    from vic_drake.estimation.palpation import PalpationData
    from vic_drake.systems.indenter import PalpationParams
    from vic_drake.tissue import load_phantom

    phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
    duration = 10.0 if ctx.options.quick else 20.0
    freqs = (2.5,) if ctx.options.quick else SIM_PALPATION_FREQUENCIES_HZ
    x, y = (np.array([v]) for v in SIM_PALPATION_POINT_M)
    truth = phantom.sample(x, y)
    logs = {}
    for k, f in enumerate(freqs):
        params = CampaignParams(palpation=PalpationParams(frequency_hz=f,
                                                          duration_s=duration), seed=k)
        ctx.progress(f"  simulating a {duration:g} s palpation at {f:g} Hz")
        (rec,) = simulate_palpations(x, y, surface_z=truth.surface_z_m, kappa=truth.kappa,
                                     lam=truth.lam, beta=phantom.beta, params=params,
                                     seed=k)
        lag = params.sensor.lag_samples / params.sensor.rate_hz
        name = f"palpation_sim_{f:g}hz"
        _write_log(ctx, name, pd.DataFrame({
            "t_s": rec.t_s, "z_m": rec.z_m, "z_target_m": rec.z_target_m,
            "force_z_N": rec.force_N,  # Positive = the body pushes the probe up.
        }), {"campaign_params": params, "point_xy_m": [float(x[0]), float(y[0])],
             "phantom": ctx.phantom_kind, "seed": k})
        data = PalpationData(t_s=rec.t_s, z_m=rec.z_m, force_N=rec.force_N,
                             surface_z_m=float(truth.surface_z_m[0]),
                             z_target_m=rec.z_target_m)
        logs[f"sim_{f:g}hz"] = (data, lag)
    out = _offline_fits(ctx, logs, "sim")
    out["truth"] = {"kappa": float(truth.kappa[0]), "lam": float(truth.lam[0])}
    return out


#: The region the paper palpated (the measured map's extent), m.
MAP_REGION_M = (-0.1587, 0.0423, -0.4145, -0.3125)


def stage_map(ctx: RunContext) -> dict:
    """Palpation campaign on a 1 cm grid, GP map of kappa and lambda, ribs.

    The campaign palpates the scan phantom (the measured map when the data is
    there, else the synthetic chest) in simulation; its GP kappa map gives C3
    "sim". The paper's own GP map (``phantom_map/``) gives C3 "real".
    """
    from vic_drake.estimation.campaign import CampaignParams, run_campaign
    from vic_drake.estimation.gp_maps import build_tissue_map
    from vic_drake.plots.maps import plot_stiffness_damping_maps, plot_surface_kappa
    from vic_drake.tissue import load_phantom

    out: dict = {}
    real_map = None
    if ctx.data_dir is not None:
        real_map = read_phantom_map(ctx.data_dir / "phantom_map")
    phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
    region = MAP_REGION_M
    if ctx.options.quick:  # A 5 cm band across the ribs (the ribs run along y).
        region = (region[0], region[1], -0.385, -0.335)
    params = CampaignParams(spacing_m=0.01, region_m=region)
    campaign = run_campaign(phantom, params, progress=lambda m: ctx.progress(f"  {m}"))
    _write_log(ctx, "campaign_points", campaign.points.drop(columns=["message"]),
               {"campaign_params": params, "phantom": ctx.phantom_kind,
                "lag_s": campaign.lag_s})
    pts = campaign.ok
    res = 0.001 if ctx.options.quick else 1e-4
    ctx.progress(f"  surface fit and GP maps every {res * 1e3:g} mm")
    tmap = build_tissue_map(campaign.points, region, beta=campaign.beta, resolution_m=res,
                            progress=lambda m: ctx.progress(f"  {m}"))
    out["ribs_sim"] = claims_mod.rib_prominences(tmap.x_m, tmap.y_m, tmap.kappa)
    out["campaign"] = campaign
    out["tissue_map"] = tmap
    # Error of the estimated kappa against the phantom, on a 1 mm subgrid.
    step = max(1, int(round(1e-3 / res)))
    xs, ys = tmap.x_m[::step], tmap.y_m[::step]
    truth = phantom.sample(*np.meshgrid(xs, ys, indexing="ij"))
    kerr = tmap.kappa[::step, ::step] - truth.kappa
    out["kappa_rel_rmse"] = float(np.sqrt(np.mean(kerr**2)) / np.mean(truth.kappa))
    ctx.add_figure(
        "Fig. 4: GP maps of kappa and lambda",
        f"GP maps every {res * 1e3:g} mm from {len(pts)} palpations simulated on a 1 cm grid "
        f"of the {ctx.phantom_kind} phantom over x {region[0]:.3f}..{region[1]:.3f} m, "
        f"y {region[2]:.3f}..{region[3]:.3f} m (dots: palpation points).",
        plot_stiffness_damping_maps(tmap), "fig4_gp_maps.png")
    ctx.add_figure(
        "Fig. 4 (comparison): estimated maps and the paper's measured map",
        "Top: the estimated maps with the detected ribs (red dotted lines); bottom (with "
        "the paper's data): the paper's own GP map. kappa relative RMS error of the "
        f"estimate against the phantom: {out['kappa_rel_rmse']:.1%}.",
        _plot_maps(tmap, pts, real_map, out["ribs_sim"],
                   claims_mod.rib_prominences(real_map.x_m, real_map.y_m, real_map.kappa)
                   if real_map is not None else None),
        "fig4_maps_vs_paper.png")
    ctx.add_figure(
        "Fig. 5: surface with elasticity",
        "The GRIDFIT-like surface through the contact points, coloured by the kappa map "
        "(the paper's Fig. 5).", plot_surface_kappa(tmap), "fig5_surface_kappa.png")
    return out


def _plot_maps(tmap, pts, real_map, ribs_sim, ribs_real):
    from matplotlib.figure import Figure

    rows = 2 if real_map is not None else 1
    fig = Figure(figsize=(11, 3.6 * rows))
    axes = fig.subplots(rows, 2, squeeze=False)
    step = max(1, int(np.ceil(tmap.x_m.size / 400)))

    def show(ax, x, y, grid, title, ribs=None):
        ext = [x[0], x[-1], y[0], y[-1]]
        im = ax.imshow(grid.T, origin="lower", extent=ext, aspect="equal", cmap="viridis")
        fig.colorbar(im, ax=ax, shrink=0.8)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        for xr in (ribs or {}).get("rib_position_m", []):
            ax.axvline(xr, color="r", ls=":", lw=1)

    xs, ys = tmap.x_m[::step], tmap.y_m[::step]
    show(axes[0, 0], xs, ys, tmap.kappa[::step, ::step], "kappa, estimated [N/m^beta]",
         ribs_sim)
    axes[0, 0].plot(pts["x_m"], pts["y_m"], "k.", ms=2)
    show(axes[0, 1], xs, ys, tmap.lam[::step, ::step],
         "lambda, estimated [N s/m^(beta+1)]")
    if real_map is not None:
        show(axes[1, 0], real_map.x_m, real_map.y_m, real_map.kappa,
             "kappa, the paper's measured map", ribs_real)
        show(axes[1, 1], real_map.x_m, real_map.y_m, real_map.lam,
             "lambda, the paper's measured map")
    fig.tight_layout()
    return fig


# --- Scans --------------------------------------------------------------------


#: Quick mode: the target starts 11 cm high (2-3 mm above the surface at the
#: start) and scans QUICK_SCAN_M along -x.
QUICK_APPROACH_Z_M = 0.11
QUICK_SCAN_M = 0.05


def scan_scenario(controller: str, *, disturbed: bool, phantom_kind: str, quick: bool):
    """The scenario of one of the paper's scans (nominal or disturbed).

    :func:`vic_drake.experiments.synthetic_scenario` (the scenarios of
    ``diagrams/``: the real rig's scan and controller settings) on the
    requested phantom, with :func:`vic_drake.experiments.disturbance_lifts`
    as the disturbance.
    Quick mode shortens the approach and the scan (QUICK_* constants) and
    has one disturbance event instead of two.
    """
    from dataclasses import replace

    from vic_drake.experiments import (
        disturbance_lifts,
        scan_start_s,
        synthetic_scenario,
    )
    from vic_drake.scenario import DisturbanceConfig

    base = synthetic_scenario(controller, disturbed=False)
    traj = base.trajectory
    if quick:
        traj = replace(traj, approach_z_m=QUICK_APPROACH_Z_M,
                       end_x_m=traj.start_x_m - QUICK_SCAN_M)
    disturbance = DisturbanceConfig()
    if disturbed:
        disturbance = DisturbanceConfig(
            lifts=disturbance_lifts(scan_start_s(traj), events=1 if quick else 2))
    cond = "disturbance" if disturbed else "nominal"
    return replace(
        base,
        name=f"{cond}_{controller.replace('-', '_')}_{phantom_kind}",
        description=f"{controller.upper()} {cond} scan on the {phantom_kind} phantom "
        f"({'quick' if quick else 'full'} mode)",
        phantom=replace(base.phantom, kind=phantom_kind),
        trajectory=traj,
        disturbance=disturbance,
    )


def scan_limits(scenario) -> claims_mod.ScanLimits:
    """K_min, T_min, P_max, eps_d of a scenario's controller."""
    c = scenario.controller
    return claims_mod.ScanLimits(
        k_min_z_N_per_m=float(c.qp.stiffness_min_N_per_m[2]),
        tank_min_J=float(c.tank.min_energy_J),
        power_max_W=float(-c.tank.power_limit_W),
        eps_d_m=float(c.reference.eps_d_m),
    )


def _run_scan_job(args):
    """Worker: one scan (module-level so a spawned process can run it)."""
    from vic_drake.experiments import run_scan

    scenario, data_dir = args
    return run_scan(scenario, data_dir=data_dir)


def stage_scans(ctx: RunContext) -> dict:
    """The four controllers nominal, VS-VF/CS/CF disturbed; logs; Fig. 6-7.

    The scans run in worker processes (one per spare core) and, for the
    nominal VS-VF scan, in this process.
    """
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from vic_drake.experiments import run_scan
    from vic_drake.scenario import save_scenario

    runs = [("nominal", c) for c in CONTROLLERS] + \
        [("disturbance", c) for c in DISTURBANCE_CONTROLLERS]
    scenarios = {
        key: scan_scenario(key[1], disturbed=key[0] == "disturbance",
                           phantom_kind=ctx.phantom_kind, quick=ctx.options.quick)
        for key in runs
    }
    logs = ctx.out_dir / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    local_key = ("nominal", "vs-vf")
    workers = max(1, (os.cpu_count() or 1) - 1)
    remote = [k for k in runs if k != local_key]
    ctx.progress(f"  {len(runs)} scans: {len(remote)} in {workers} worker process(es), "
                 f"{local_key[1]} {local_key[0]} in this one")
    results = {}
    with ProcessPoolExecutor(max_workers=workers,
                             mp_context=multiprocessing.get_context("spawn")) as pool:
        futures = {pool.submit(_run_scan_job, (scenarios[k], ctx.data_dir)): k
                   for k in remote}
        t0 = time.perf_counter()
        results[local_key] = run_scan(scenarios[local_key], data_dir=ctx.data_dir)
        _report_scan(ctx, scenarios[local_key], results[local_key], len(results), len(runs))
        from concurrent.futures import as_completed

        for fut in as_completed(futures):
            k = futures[fut]
            results[k] = fut.result()
            _report_scan(ctx, scenarios[k], results[k], len(results), len(runs))
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
        lim = scan_limits(scenario)
        limits = limits or lim
        frames[cond][ctrl] = df
        metrics[cond][ctrl] = claims_mod.scan_metrics(df, limits=lim)
        timing.append([scenario.name, result.sim_s, result.wall_s, result.rtf])
    _scan_figures(ctx, frames)
    from vic_drake.report import ReportTable

    ctx.tables.append(ReportTable(
        "Simulated scans: timing", ["run", "simulated [s]", "wall [s]", "real-time factor"],
        timing, f"{workers} worker process(es) plus the main process."))
    return {"frames": frames, "metrics": metrics, "limits": limits, "timing": timing,
            "scenarios": scenarios}


def _report_scan(ctx, scenario, result, done: int, total: int) -> None:
    ctx.progress(f"  scan {done}/{total} {scenario.name}: {result.sim_s:.1f} s simulated "
                 f"in {result.wall_s:.1f} s (real-time factor {result.rtf:.2f})")


def _scan_figures(ctx: RunContext, frames: dict) -> None:
    from vic_drake.plots.scans import plot_fig6, plot_fig7

    real = (ctx.results.get("real_scans") or {}).get("frames", {})
    nominal = {k: frames["nominal"][k] for k in ("vs-cf", "vs-vf") if k in frames["nominal"]}
    if nominal:
        ctx.add_figure("Fig. 6: VS-CF and VS-VF, nominal",
                       "Simulated scans (and the real logs where they exist): force with "
                       "F_ref and F_min, K_z, penetration, tank energy.",
                       plot_fig6(nominal, real.get("nominal")), "fig6_nominal.png")
    base = {k: frames["nominal"][k] for k in ("cs", "cf") if k in frames["nominal"]}
    if base:
        ctx.add_figure("CS and CF, nominal (not in the paper's Fig. 6)",
                       "The baselines' nominal scans, same layout as Fig. 6.",
                       plot_fig6(base, real.get("nominal")), "fig6_baselines.png")
    dist = {k: frames["disturbance"][k] for k in DISTURBANCE_CONTROLLERS
            if k in frames["disturbance"]}
    if dist:
        ctx.add_figure("Fig. 7: VS-VF, CS, CF with the phantom lifted",
                       "Phantom lifted and dropped during the scan: force, tip height with "
                       "the moving surface, K_z (real _dist logs of CS and CF overlaid).",
                       plot_fig7(dist, real.get("disturbance")), "fig7_disturbance.png")


#: Frames per second of the Meshcat replay.
REPLAY_FPS = 25.0


def replay_scan(df: pd.DataFrame, scenario, *, phantom, fps: float = REPLAY_FPS) -> str:
    """A standalone Meshcat HTML animation of a logged scan.

    The station (arm, tool, phantom) is posed at every frame from the log: the
    joint angles commanded by FDCC (``q_cmd_*_rad``; the arm's servo follows
    them within a few ms) and the phantom's lift (``phantom_lift_m``), and
    published into a Meshcat recording; no simulation runs.

    Returns:
        The HTML text (``Meshcat.StaticHtml()``).
    """
    from pydrake.geometry import Meshcat
    from pydrake.systems.framework import DiagramBuilder

    from vic_drake.station import MakeStation, set_station_state

    q_cols = [f"q_cmd_{i}_rad" for i in range(6)]
    missing = [c for c in [*q_cols, "t_s", "phantom_lift_m"] if c not in df.columns]
    if missing:
        raise VicDrakeError(f"replay_scan: the log lacks columns {missing}")
    meshcat = Meshcat()
    builder = DiagramBuilder()
    station = builder.AddNamedSystem(
        "station", MakeStation(scenario.station, phantom=phantom, meshcat=meshcat))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    station_context = station.GetMyMutableContextFromRoot(context)
    t = df["t_s"].to_numpy()
    frames = np.arange(t[0], t[-1], 1.0 / fps)
    idx = np.searchsorted(t, frames).clip(0, len(t) - 1)
    q = df[q_cols].to_numpy()
    lift = df["phantom_lift_m"].to_numpy()
    meshcat.StartRecording(frames_per_second=fps, set_visualizations_while_recording=False)
    for i, tf in zip(idx, frames):
        context.SetTime(float(tf))
        set_station_state(station, station_context, q[i], phantom_lift_m=float(lift[i]))
        diagram.ForcedPublish(context)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    return meshcat.StaticHtml()


def stage_replay(ctx: RunContext) -> dict:
    """The nominal VS-VF scan as a standalone Meshcat animation (replay.html)."""
    from vic_drake.tissue import load_phantom

    scans = ctx.results.get("scans")
    if not scans:
        raise StageSkipped("no simulated scan to replay (the scans stage did not run)")
    key = ("nominal", "vs-vf")
    df = scans["frames"][key[0]][key[1]]
    scenario = scans["scenarios"][key]
    phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
    html = replay_scan(df, scenario, phantom=phantom)
    path = ctx.out_dir / "replay.html"
    path.write_text(html, encoding="utf-8")
    return {"path": path, "bytes": path.stat().st_size, "scenario": scenario.name}


def _compare_real_job(args):
    """Worker: one real experiment re-run in simulation (module-level for spawn)."""
    from vic_drake.experiments import compare_real

    bag, data_dir = args
    return compare_real(bag, data_dir=data_dir, return_frames=True)


#: Keys of vic_drake.experiments.compare_real shown in the report.
COMPARE_REAL_KEYS = ("controller", "duration_s", "force_rmse_N", "force_peak_err_N",
                     "z_rmse_mm", "kz_corr", "tank_min_J", "rtf")


def stage_compare_real(ctx: RunContext) -> dict:
    """Each real scan re-run in simulation on the measured map, compared with its log.

    :func:`vic_drake.experiments.compare_real` (logged target, controller
    settings, estimated phantom lift of the ``_dist`` logs). Full mode only.
    """
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    if ctx.data_dir is None:
        raise StageSkipped("no real data (pass --data-dir or set VIC_DRAKE_DATA)")
    if ctx.options.quick:
        raise StageSkipped("full mode only (six more simulations of 20-26 s)")
    names = sorted(set(REAL_SCAN_LOGS.values()))
    workers = max(1, min(len(names), os.cpu_count() or 1))
    out = {}
    with ProcessPoolExecutor(max_workers=workers,
                             mp_context=multiprocessing.get_context("spawn")) as pool:
        jobs = {name: pool.submit(_compare_real_job,
                                  (ctx.data_dir / "experiments" / name, ctx.data_dir))
                for name in names}
        for name, fut in jobs.items():
            out[name] = fut.result()
            ctx.progress(f"  {name}: force RMSE {out[name][0]['force_rmse_N']:.2f} N, "
                         f"z RMSE {out[name][0]['z_rmse_mm']:.1f} mm")
    from vic_drake.report import ReportTable

    ctx.tables.append(ReportTable(
        "Real experiments re-run in simulation (measured map)",
        ["log", *COMPARE_REAL_KEYS],
        [[name, *(res[0].get(k) for k in COMPARE_REAL_KEYS)] for name, res in out.items()],
        "vic_drake.experiments.compare_real: each real scan's target, controller settings "
        "and (for _dist logs) estimated phantom lift, simulated and compared with the log "
        "after time alignment. kz_corr: correlation of simulated and logged K_z."))
    from vic_drake.plots.scans import plot_comparison

    for name in ("test_nardi_matForce_lowR", "test_compliance_control400_dist"):
        if name in out:
            _, sim_df, real_df = out[name]
            ctx.add_figure(f"Real vs simulated: {name}",
                           "The real log and its simulation on the measured map.",
                           plot_comparison(sim_df, real_df, title=name),
                           f"compare_real_{name}.png")
    return {name: res[0] for name, res in out.items()}


# --- Claims and report --------------------------------------------------------


def gather_claim_inputs(ctx: RunContext) -> claims_mod.ClaimInputs:
    """Collects what the claims need from the stage results, with reasons."""
    r = ctx.results
    inp = claims_mod.ClaimInputs()
    reasons = inp.reasons

    def reason(stage: str) -> str:
        return ctx.stage_error(stage) or "result missing"

    off_real, off_sim = r.get("offline_real"), r.get("offline_sim")
    if off_real:
        inp.residuals_real = off_real.get("residuals")
        inp.decay_real = off_real.get("decay")
    for cid in ("C1", "C2"):
        reasons[f"{cid}.real"] = reason("offline_real")
        reasons[f"{cid}.sim"] = reason("offline_sim")
    if off_sim:
        inp.residuals_sim = off_sim.get("residuals")
        inp.decay_sim = off_sim.get("decay")
    mp = r.get("map")
    if mp:
        inp.ribs_sim = mp.get("ribs_sim")
    reasons["C3.sim"] = reason("map")
    reasons["C3.real"] = reason("real_scans")
    scans = r.get("scans")
    if scans:
        inp.nominal_sim = scans["metrics"].get("nominal")
        inp.disturbance_sim = scans["metrics"].get("disturbance")
        if scans.get("limits") is not None:
            inp.limits = scans["limits"]
    for cid in ("C4", "C5", "C6", "C7"):
        reasons[f"{cid}.sim"] = reason("scans")
        reasons[f"{cid}.real"] = reason("real_scans")
    rs = r.get("real_scans")
    if rs:
        inp.ribs_real = rs.get("ribs")
        inp.nominal_real = rs["metrics"].get("nominal")
        inp.disturbance_real = rs["metrics"].get("disturbance")
        reasons["C7.real"] = "the published data has no VS-VF disturbance log"
        reasons["C6.real"] = "the VS-VF log lacks the needed columns"
    return inp


def stage_claims(ctx: RunContext) -> dict:
    """C1-C7 -> claims.json."""
    inp = gather_claim_inputs(ctx)
    claims = claims_mod.evaluate_claims(inp)
    as_dict = claims_mod.claims_to_json_dict(claims)
    path = ctx.out_dir / "claims.json"
    from vic_drake.commands.common import to_json

    path.write_text(to_json(as_dict) + "\n", encoding="utf-8")
    # Real scan metrics as a table.
    rs = ctx.results.get("real_scans")
    if rs:
        _metrics_table(ctx, "Real scan logs: metrics", rs["metrics"])
    sc = ctx.results.get("scans")
    if sc:
        _metrics_table(ctx, "Simulated scans: metrics", sc["metrics"])
    return {"claims": as_dict, "path": path}


_TABLE_KEYS = ("force_rmse_N", "force_range_N", "peak_force_N", "lifted_off",
               "penetration_error_off_ribs_median_m", "force_on_ribs_p99_N",
               "n_contact_losses", "fraction_at_k_min_during_loss", "tank_min_J",
               "tank_power_min_W")


def _metrics_table(ctx: RunContext, title: str, metrics: dict) -> None:
    from vic_drake.report import ReportTable

    rows = []
    for cond, by_ctrl in metrics.items():
        for ctrl, m in by_ctrl.items():
            rows.append([cond, ctrl, *(m.get(k) for k in _TABLE_KEYS)])
    if rows:
        ctx.tables.append(ReportTable(title, ["condition", "controller", *_TABLE_KEYS], rows,
                                      "See vic_drake.claims.scan_metrics for definitions."))


def _versions() -> dict:
    import matplotlib
    import scipy
    import sklearn

    import vic_drake

    try:
        import pydrake

        drake_version = getattr(pydrake, "__version__", "unknown")
    except ImportError:  # pragma: no cover - drake is a dependency
        drake_version = "not installed"
    return {
        "vic_drake": vic_drake.__version__, "drake": drake_version,
        "python": platform.python_version(), "numpy": np.__version__,
        "scipy": scipy.__version__, "pandas": pd.__version__,
        "scikit-learn": sklearn.__version__, "matplotlib": matplotlib.__version__,
    }


REPORT_NOTES = (
    "paper: the paper's number or statement; simulation: the same metric computed from "
    "the logs of the Drake simulation; real measurement: the same metric on the paper's "
    "own logs (../shared/data), where such a log exists.",
    "C1 and C2 in simulation fit palpations simulated on a Hunt-Crossley tissue with "
    "beta = 1.35: they test the estimation pipeline (sensor lag and noise, indenter mass, "
    "contact selection), not whether tissue is Hunt-Crossley; the real logs test that.",
    "C2 in simulation: the simulated tissue IS the fitted model, so a short palpation "
    "already fits it and the residual barely falls; the several-fold fall of the real "
    "logs comes from what the model lacks (drift, non-stationarity, model mismatch).",
    "C3 in simulation re-estimates the scan phantom's map from simulated palpations on "
    "a 1 cm grid (with the paper's data, the phantom is the paper's measured map); the "
    "real value is the paper's own GP map.",
    "C4-C7 in simulation come from the scans of this run; the real values from the "
    "paper's scan logs. The published data has no VS-VF disturbance log, so C7 has no "
    "real value. The real CF reference (7 N) is not logged; it is taken from the "
    "data's README.",
    "The disturbance here is a scripted lift, drop below rest and return of the phantom "
    "(vic_drake.experiments.disturbance_lifts); the paper's was by hand, so peak forces "
    "compare in order, not in value.",
    "Quick mode scans 5 cm instead of 20 cm with one disturbance event; force ranges "
    "(C5) and peak forces (C7) see less of the body than the full run.",
)


_PAPER_ORDER = (("Fig. 2", 2.0), ("Table I", 2.5), ("Beta sweep", 2.6), ("Fig. 3", 3.0),
                ("Fig. 4", 4.0), ("Fig. 5", 5.0), ("Fig. 6", 6.0), ("CS and CF", 6.5),
                ("Fig. 7", 7.0), ("Real scan logs", 8.0), ("Simulated scans: metrics", 8.1),
                ("Real experiments", 8.5), ("Real vs simulated", 8.6))


def _paper_order(title: str) -> float:
    """Rank of a figure or table: the paper's order, then the rest."""
    return next((rank for prefix, rank in _PAPER_ORDER if title.startswith(prefix)), 9.0)


def stage_report(ctx: RunContext) -> dict:
    """report.html: claims, tables, figures, files, stage times, versions."""
    from vic_drake.report import ReportContent, write_report

    claims = (ctx.results.get("claims") or {}).get("claims", {})
    links = []
    replay = ctx.results.get("replay")
    if replay and replay.get("path"):
        links.append(("Meshcat replay of one scan (open in a browser)",
                      os.path.relpath(replay["path"], ctx.out_dir)))
    links.append(("claims.json", "claims.json"))
    logs_dir = ctx.out_dir / "logs"
    if logs_dir.is_dir():
        for p in sorted(logs_dir.iterdir()):
            links.append((f"logs/{p.name}", f"logs/{p.name}"))
    mode = "quick" if ctx.options.quick else "full"
    content = ReportContent(
        title="vic_drake: reproduction of Beber et al., passive variable impedance "
        "control for safe ultrasonography",
        summary=(
            f"Mode: {mode}. Phantom for the simulated scans: {ctx.phantom_kind}. "
            f"Real data: {ctx.data_dir if ctx.data_dir else 'not found'}. Each claim is a "
            "metric computed from logged signals, in simulation and in the paper's real "
            "logs where they exist."
        ),
        claims=claims,
        figures=sorted(ctx.figures, key=lambda f: _paper_order(f.title)),
        tables=sorted(ctx.tables, key=lambda t: _paper_order(t.title)),
        metadata={
            **{f"version {k}": v for k, v in _versions().items()},
            "data folder": str(ctx.data_dir) if ctx.data_dir else "not found",
            "mode": mode,
            "phantom": ctx.phantom_kind,
            "machine": f"{platform.machine()}, {os.cpu_count()} CPUs",
            "total wall time [s]": round(sum(r.wall_s for r in ctx.records), 1),
            "date (UTC)": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime()),
        },
        stages=[r.as_dict() for r in ctx.records],
        links=links,
        notes=REPORT_NOTES,
    )
    path = write_report(content, ctx.out_dir / "report.html")
    return {"path": path}


STAGES: tuple[tuple[str, Callable[[RunContext], Any]], ...] = (
    ("offline_real", stage_offline_real),
    ("offline_sim", stage_offline_sim),
    ("map", stage_map),
    ("real_scans", stage_real_scans),
    ("scans", stage_scans),
    ("replay", stage_replay),
    ("compare_real", stage_compare_real),
    ("claims", stage_claims),
    ("report", stage_report),
)
STAGE_NAMES = tuple(name for name, _ in STAGES)


@dataclass
class ReproduceResult:
    """What a run produced."""

    out_dir: Path
    claims: dict
    records: list[StageRecord]
    wall_s: float
    report_path: Path | None
    results: dict

    def summary(self) -> dict:
        return {
            "out_dir": str(self.out_dir),
            "report": str(self.report_path) if self.report_path else None,
            "wall_s": round(self.wall_s, 1),
            "stages": [r.as_dict() for r in self.records],
            "claims": {k: bool(v["pass"]) for k, v in self.claims.items()},
        }


def run_pipeline(ctx: RunContext) -> None:
    """Runs the selected stages in order, timing and recording each."""
    selected = ctx.options.stages
    names = [n for n, _ in STAGES if selected is None or n in selected]
    # claims and report always run last when anything ran.
    for i, (name, fn) in enumerate((n, f) for n, f in STAGES if n in names):
        ctx.progress(f"[{i + 1}/{len(names)}] {name} ...")
        t0 = time.perf_counter()
        try:
            ctx.results[name] = fn(ctx)
            rec = StageRecord(name, True, time.perf_counter() - t0)
            ctx.progress(f"[{i + 1}/{len(names)}] {name} done in {rec.wall_s:.1f} s")
        except StageSkipped as exc:
            rec = StageRecord(name, False, time.perf_counter() - t0, f"skipped: {exc}",
                              skipped=True)
            ctx.progress(f"[{i + 1}/{len(names)}] {name} skipped: {exc}")
        except Exception as exc:  # noqa: BLE001 - a failed stage is reported, not fatal
            msg = f"{type(exc).__name__}: {exc}"
            rec = StageRecord(name, False, time.perf_counter() - t0, msg)
            ctx.progress(f"[{i + 1}/{len(names)}] {name} FAILED: {msg}")
            log = ctx.out_dir / "logs" / "errors.txt"
            log.parent.mkdir(parents=True, exist_ok=True)
            with log.open("a", encoding="utf-8") as fh:
                fh.write(f"--- stage {name}\n{traceback.format_exc()}\n")
        ctx.records.append(rec)


def reproduce(options: ReproduceOptions) -> ReproduceResult:
    """Runs the reproduction; returns the claims and where everything is.

    Raises:
        VicDrakeError: the output folder cannot be created.
    """
    try:
        options.out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise VicDrakeError(f"cannot create the output folder {str(options.out_dir)!r}: "
                            f"{exc.strerror}") from None
    err_log = options.out_dir / "logs" / "errors.txt"
    if err_log.exists():
        err_log.unlink()
    ctx = RunContext(options)
    t0 = time.perf_counter()
    run_pipeline(ctx)
    wall = time.perf_counter() - t0
    (options.out_dir / "run.json").write_text(
        json.dumps({"wall_s": round(wall, 2), "quick": options.quick,
                    "stages": [r.as_dict() for r in ctx.records]}, indent=2) + "\n",
        encoding="utf-8")
    claims = (ctx.results.get("claims") or {}).get("claims", {})
    report = (ctx.results.get("report") or {}).get("path")
    return ReproduceResult(options.out_dir, claims, ctx.records, wall, report, ctx.results)


__all__ = [
    "CONTROLLERS",
    "DISTURBANCE_CONTROLLERS",
    "REAL_SCAN_LOGS",
    "ReproduceOptions",
    "ReproduceResult",
    "RunContext",
    "STAGES",
    "STAGE_NAMES",
    "StageRecord",
    "StageSkipped",
    "real_scan_frame",
    "reproduce",
    "run_pipeline",
]
