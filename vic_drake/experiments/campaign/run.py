"""One campaign run on a worker: scenario text in, a plain result row out.

:func:`execute_run` is what a Dask worker executes. It builds its own
Diagram from the run's scenario YAML (Diagrams, Simulators and Contexts do
not pickle), simulates it and reduces the log to :func:`run_metrics`. A run
that raises is a row with ``status = "error"`` and the error's text; a run
whose log holds NaN is ``status = "nan"``. Neither stops the campaign.
"""

from __future__ import annotations

import math
import time
import traceback

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import require_columns
from vic_drake.analysis.contact import contact_loss_intervals, scan_window
from vic_drake.analysis.scan_metrics import tank_min_J
from vic_drake.control.references import has_tank
from vic_drake.experiments.campaign.plan import RunPlan
from vic_drake.provenance import code_id
from vic_drake.scenario import dumps_scenario

#: The columns whose non-finite values make a run a NaN run.
CHECKED_COLUMNS = ("z_m", "force_sensor_z_N", "force_tissue_z_N", "stiffness_z_N_per_m")

#: The metric keys of every row, in order (NaN where a run has none).
METRIC_KEYS = (
    "peak_force_N",
    "p99_force_N",
    "time_above_limit_s",
    "contact_loss_s",
    "tank_min_J",
    "tank_floor_J",
    "qp_failures",
    "input_faults",
    "watchdog_trip_s",
)


def run_metrics(
    df: pd.DataFrame,
    *,
    force_limit_N: float,
    has_tank: bool = True,
    stop_s: float = math.nan,
) -> dict:
    """The safety metrics of one run's log.

    The force is the tissue's force on the probe (``force_tissue_z_N``, the
    force on the patient, not what a faulty sensor reports). Contact losses
    are :func:`vic_drake.analysis.contact.contact_loss_intervals` inside the
    scan window, which ends at ``stop_s`` when that is finite (the time the
    force sensor's watchdog stopped the scan: the retract after it is the
    stop, not a loss of contact). ``qp_failures`` counts logged samples
    whose stiffness QP failed (``qp_ok`` = 0, ``qp_fault`` = 0),
    ``input_faults`` those the controller skipped on a non-finite input
    (``qp_fault`` = 1: a NaN reading; K is held at K_min), and
    ``tank_min_J`` is the tank's lowest energy, all before ``stop_s``: after
    the stop the controller's QP and tank still run on the stale sensor,
    but the arm no longer follows them.
    ``tank_min_J`` is NaN for a controller without a tank (``has_tank``
    False: CS, CF).
    """
    t = df["t_s"].to_numpy(float)
    f = df["force_tissue_z_N"].to_numpy(float)
    dt = np.diff(t, append=t[-1] + (t[-1] - t[-2] if t.size > 1 else 0.0))
    window = scan_window(df)
    driven = t < stop_s if math.isfinite(stop_s) else np.ones(t.size, bool)
    window &= driven
    losses = contact_loss_intervals(df, window=window)
    require_columns(df, "qp_ok", "qp_fault")
    qp_ok = df["qp_ok"].to_numpy(float) > 0.5
    faulted = df["qp_fault"].to_numpy(float) > 0.5
    return {
        "peak_force_N": float(np.nanmax(f)),
        "p99_force_N": float(np.nanpercentile(f, 99)),
        "time_above_limit_s": float(dt[f > force_limit_N].sum()),
        "contact_loss_s": float(sum(b - a for a, b in losses)),
        "tank_min_J": tank_min_J(df[driven], has_tank=has_tank),
        "qp_failures": int(np.sum(~qp_ok & ~faulted & driven)),
        "input_faults": int(np.sum(faulted & driven)),
    }


def _nan_columns(df: pd.DataFrame) -> list[str]:
    return [
        c for c in CHECKED_COLUMNS if not np.all(np.isfinite(df[c].to_numpy(float)))
    ]


def execute_run(plan: RunPlan) -> dict:
    """Simulates one run; never raises for a run's own failure.

    Returns:
        A row: run_id, index, status ("ok" | "nan" | "error"), error (text,
        "" when ok), code_id (:func:`vic_drake.provenance.code_id` of the
        process that ran it), the sampled factors (``factor.<name>``), the metrics of
        :data:`METRIC_KEYS` (``watchdog_trip_s``: when the force sensor's
        watchdog stopped the scan, NaN if it did not), ``watchdog_cause``
        (what stopped it: "x", "y" or "z" for a stuck channel, "all" for a
        dead sensor, "" if nothing did), sim_s and wall_s; and
        ``_scenario_yaml``, the run's exact scenario, which the engine stores
        beside the row.
    """
    # Imported here: a worker process pays pydrake's import on its first run.
    from vic_drake.experiments.scan_run import run_scan

    t0 = time.perf_counter()
    row = {"run_id": plan.run_id, "index": plan.index, "status": "ok", "error": ""}
    row["code_id"] = code_id()
    row.update({f"factor.{k}": v for k, v in plan.factors.items()})
    row.update({k: math.nan for k in METRIC_KEYS})
    row["watchdog_cause"] = ""
    row["sim_s"] = plan.duration_s
    try:
        scenario = plan.scenario()
        row["_scenario_yaml"] = dumps_scenario(scenario)
        tank = has_tank(scenario.controller.reference)
        # CS and CF have no tank: no floor, no minimum (NaN).
        if tank:
            row["tank_floor_J"] = float(scenario.controller.tank.min_energy_J)
        result = run_scan(scenario, duration_s=plan.duration_s)
        df = result.df
        bad = _nan_columns(df)
        with np.errstate(all="ignore"):
            row.update(
                run_metrics(
                    df,
                    force_limit_N=plan.force_limit_N,
                    has_tank=tank,
                    stop_s=result.watchdog_trip_s,
                )
            )
        row["watchdog_trip_s"] = result.watchdog_trip_s
        row["watchdog_cause"] = result.watchdog_cause
        if bad:
            row["status"] = "nan"
            first = float(
                df["t_s"].to_numpy()[~np.isfinite(df[bad[0]].to_numpy(float))][0]
            )
            row["error"] = f"non-finite values in {bad} from t = {first:.3f} s"
    except Exception as exc:  # noqa: BLE001 - a run's failure is data.
        row["status"] = "error"
        tb = traceback.extract_tb(exc.__traceback__)
        where = f" at {tb[-1].filename}:{tb[-1].lineno}" if tb else ""
        row["error"] = f"{type(exc).__name__}: {exc}{where}"
    row["wall_s"] = time.perf_counter() - t0
    return row


def execute_run_in_child(plan: RunPlan) -> dict:
    """:func:`execute_run` in a fresh Python process
    (:func:`~vic_drake.experiments.child_process.run_in_child`: a worker
    does not grow by each run's Diagram, and a crash costs this run only,
    an error row); what the workers run."""
    from vic_drake.experiments.child_process import ChildFailed, run_in_child

    t0 = time.perf_counter()
    try:
        return run_in_child(execute_run, plan)
    except ValueError as exc:  # VIC_DRAKE_ALLOCATOR on this worker's machine.
        return failed_row(plan, str(exc), wall_s=0.0)
    except ChildFailed as exc:
        return failed_row(plan, str(exc), wall_s=time.perf_counter() - t0)


def failed_row(plan: RunPlan, error: str, *, wall_s: float = math.nan) -> dict:
    """The row of a run that produced no log (its metrics NaN)."""
    row = {
        "run_id": plan.run_id,
        "index": plan.index,
        "status": "error",
        "error": error,
        "code_id": code_id(),
    }
    row.update({f"factor.{k}": v for k, v in plan.factors.items()})
    row.update({k: math.nan for k in METRIC_KEYS})
    row.update(watchdog_cause="", sim_s=plan.duration_s, wall_s=wall_s)
    return row


__all__ = [
    "CHECKED_COLUMNS",
    "METRIC_KEYS",
    "execute_run",
    "execute_run_in_child",
    "failed_row",
    "run_metrics",
]
