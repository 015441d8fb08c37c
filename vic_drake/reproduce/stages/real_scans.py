"""Stage ``real_scans``: the paper's scan logs reduced to the claims' metrics.

Also the ribs of the paper's measured kappa map (C3 "real").
"""

from __future__ import annotations

import pandas as pd

from vic_drake.analysis import claims as claims_mod
from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.ribs import rib_prominences
from vic_drake.realdata import read_bag, read_phantom_map
from vic_drake.reproduce.context import RunContext, StageSkipped

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


def real_scan_frame(df: pd.DataFrame, *, controller: str | None = None) -> pd.DataFrame:
    """A real scan log in the canonical scan columns (those it has).

    Args:
        df: :func:`vic_drake.realdata.read_bag` output of a 9-column (CS/CF)
            or 31-column (variable impedance) log.
        controller: for the 9-column layout, "cf" adds the 7 N reference the
            rig used (not logged); "cs" has no force reference.

    Returns:
        :func:`vic_drake.analysis.columns.real_to_canonical` without the columns the
        log does not hold (9-column: pose, z target, sensor z force,
        contact; 31-column: also the controller's signals).

    Raises:
        VicDrakeError: a log that is not a scan log.
    """
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
    ribs = rib_prominences(m.x_m, m.y_m, m.kappa)
    return {"frames": frames, "metrics": metrics, "ribs": ribs}
