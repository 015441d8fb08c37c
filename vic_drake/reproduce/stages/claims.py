"""Stage ``claims``: the claims C1-C7 from the stage results -> claims.json.

Also the metrics tables of the real and the simulated scans.
"""

from __future__ import annotations

from vic_drake.analysis import claims as claims_mod
from vic_drake.jsonio import to_json
from vic_drake.reproduce.context import RunContext
from vic_drake.reproduce.report import ReportTable

#: Metrics of vic_drake.analysis.claims.scan_metrics shown in the scan tables.
_TABLE_KEYS = (
    "force_rmse_N",
    "force_range_N",
    "peak_force_N",
    "lifted_off",
    "penetration_error_off_ribs_median_m",
    "force_on_ribs_p99_N",
    "n_contact_losses",
    "fraction_at_k_min_during_loss",
    "tank_min_J",
    "tank_power_min_W",
)

#: (key, column name, factor to it): a length in m reads in mm.
_TABLE_COLUMNS = tuple(
    (k, k[:-2] + "_mm", 1e3) if k.endswith("_m") else (k, k, None) for k in _TABLE_KEYS
)


def _cell(value, scale):
    # NaN (CS's and CF's tank: they have none) shows as a missing metric
    # does: a dash.
    if value is None or value != value:
        return None
    return value if scale is None else value * scale


def gather_claim_inputs(ctx: RunContext) -> claims_mod.ClaimInputs:
    """Collects what the claims need from the stage results, with reasons."""
    r = ctx.results
    inp = claims_mod.ClaimInputs()
    reasons = inp.reasons

    def reason(stage: str) -> str:
        return ctx.stage_error(stage) or f"the {stage} stage returned no result"

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
    path.write_text(to_json(as_dict) + "\n", encoding="utf-8")
    # Real scan metrics as a table.
    rs = ctx.results.get("real_scans")
    if rs:
        _metrics_table(ctx, "Real scan logs: metrics", rs["metrics"])
    sc = ctx.results.get("scans")
    if sc:
        _metrics_table(ctx, "Simulated scans: metrics", sc["metrics"])
    return {"claims": as_dict, "path": path}


def _metrics_table(ctx: RunContext, title: str, metrics: dict) -> None:
    rows = []
    for cond, by_ctrl in metrics.items():
        for ctrl, m in by_ctrl.items():
            cells = (_cell(m.get(k), scale) for k, _, scale in _TABLE_COLUMNS)
            rows.append([cond, ctrl, *cells])
    if rows:
        ctx.tables.append(
            ReportTable(
                title,
                ["condition", "controller", *(name for _, name, _ in _TABLE_COLUMNS)],
                rows,
                "See vic_drake.analysis.claims.scan_metrics for definitions.",
            )
        )
