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

    def as_dict(self) -> dict:
        return {"name": self.name, "ok": self.ok, "wall_s": round(self.wall_s, 2),
                "error": self.error}


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


# --- Real scan logs -----------------------------------------------------------


def real_scan_frame(df: pd.DataFrame, *, controller: str | None = None) -> pd.DataFrame:
    """A real scan log in the canonical scan columns (those it has).

    Args:
        df: :func:`vic_drake.realdata.read_bag` output of a 9-column (CS/CF)
            or 31-column (variable impedance) log.
        controller: for the 9-column layout, "cf" adds the 7 N reference the
            rig used (not logged); "cs" has no force reference.

    Returns:
        DataFrame with t_s, x_m, y_m, z_m, z_d_m, force_sensor_z_N (sensor
        sign: negative = pressing) and, for the 31-column layout,
        force_ref_z_N, force_min_z_N, penetration_m, stiffness_*_N_per_m,
        tank_energy_J, tank_power_W (tank change / tick period).
    """
    layout = df.attrs.get("layout")
    if layout == "scan":
        out = pd.DataFrame({
            "t_s": df["t_s"], "x_m": df["x_m"], "y_m": df["y_m"], "z_m": df["z_m"],
            "z_d_m": df["z_target_m"], "force_sensor_z_N": -df["force_pressing_z_N"],
        })
        if controller == "cf":
            out["force_ref_z_N"] = -REAL_CF_REFERENCE_N
        return out
    if layout == "controller":
        dt = np.diff(df["t_s"].to_numpy(), prepend=np.nan)
        dt[0] = dt[1] if len(dt) > 1 else np.nan
        return pd.DataFrame({
            "t_s": df["t_s"], "x_m": df["x_m"], "y_m": df["y_m"], "z_m": df["z_m"],
            "x_d_m": df["x_d_m"], "y_d_m": df["y_d_m"], "z_d_m": df["z_d_m"],
            "force_sensor_x_N": df["sensor_force_x_N"],
            "force_sensor_y_N": df["sensor_force_y_N"],
            "force_sensor_z_N": df["sensor_force_z_N"],
            "force_ref_z_N": df["force_ref_z_N"], "force_min_z_N": df["force_min_z_N"],
            "penetration_m": df["penetration_m"],
            "stiffness_x_N_per_m": df["stiffness_x_N_per_m"],
            "stiffness_y_N_per_m": df["stiffness_y_N_per_m"],
            "stiffness_z_N_per_m": df["stiffness_z_N_per_m"],
            "tank_energy_J": df["tank_energy_J"],
            "tank_power_W": df["tank_delta_J"].to_numpy() / np.where(dt > 0, dt, np.nan),
        })
    raise VicDrakeError(
        f"real_scan_frame: log layout {layout!r} is not a scan log; needs 'scan' (9 "
        "columns) or 'controller' (31 columns)"
    )


def stage_real_scans(ctx: RunContext) -> dict:
    """The paper's scan logs -> canonical frames and claim metrics."""
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
    return {"frames": frames, "metrics": metrics}


# --- Offline estimation -------------------------------------------------------


def stage_offline_real(ctx: RunContext) -> dict:
    """Table I, the beta sweep, residual vs time and the load test on real logs."""
    if ctx.data_dir is None:
        raise StageSkipped("no real data (pass --data-dir or set VIC_DRAKE_DATA)")
    raise StageSkipped("vic_drake.estimation.palpation is not available yet")


def stage_offline_sim(ctx: RunContext) -> dict:
    """The palpation fits on palpations simulated on the phantom."""
    raise StageSkipped("simulated palpation is not available yet")


def stage_map(ctx: RunContext) -> dict:
    """Rib detection on the measured map; the estimated map when B's API exists."""
    out: dict = {}
    if ctx.data_dir is not None:
        m = read_phantom_map(ctx.data_dir / "phantom_map")
        out["ribs_real"] = claims_mod.rib_prominences(m.x_m, m.y_m, m.kappa)
    out["ribs_sim"] = None
    out["reason_sim"] = "vic_drake.estimation.campaign is not available yet"
    return out


def stage_scans(ctx: RunContext) -> dict:
    """Nominal and disturbance scans in simulation."""
    raise StageSkipped("vic_drake.experiments.run_scan is not available yet")


def stage_replay(ctx: RunContext) -> dict:
    """A Meshcat replay of one scan, as a standalone HTML file."""
    raise StageSkipped("vic_drake.experiments.MakeScanDiagram is not available yet")


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
        inp.ribs_real = mp.get("ribs_real")
        inp.ribs_sim = mp.get("ribs_sim")
        reasons["C3.sim"] = mp.get("reason_sim") or reason("map")
        reasons["C3.real"] = "no real data" if ctx.data_dir is None else reason("map")
    else:
        reasons["C3.sim"] = reasons["C3.real"] = reason("map")
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
        figures=ctx.figures,
        tables=ctx.tables,
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
    )
    path = write_report(content, ctx.out_dir / "report.html")
    return {"path": path}


STAGES: tuple[tuple[str, Callable[[RunContext], Any]], ...] = (
    ("offline_real", stage_offline_real),
    ("offline_sim", stage_offline_sim),
    ("map", stage_map),
    ("scans", stage_scans),
    ("real_scans", stage_real_scans),
    ("replay", stage_replay),
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
            rec = StageRecord(name, False, time.perf_counter() - t0, f"skipped: {exc}")
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
