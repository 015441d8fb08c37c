"""The pipeline: the stages in order, each timed and recorded; the run's result.

:func:`run_pipeline` runs the selected stages of :data:`STAGES` in order,
times each, shows progress, and records a stage that fails (its error
message, the traceback in ``logs/errors.txt``) instead of stopping: the
claims that need a failed stage are then reported as not evaluated, with the
reason (never as a fail). :func:`reproduce` is the library entry point.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vic_drake.analysis.claims import PASS, claim_status
from vic_drake.paths import find_data_dir
from vic_drake.reproduce.context import RunContext, StageRecord, StageSkipped
from vic_drake.reproduce.interrupt import interrupted, sigint_watch
from vic_drake.reproduce.options import ReproduceOptions
from vic_drake.reproduce.run_dir import RUN_FILE, finish_run_dir, prepare_run_dir
from vic_drake.reproduce.stages.claims import stage_claims
from vic_drake.reproduce.stages.compare_real import stage_compare_real
from vic_drake.reproduce.stages.map import stage_map
from vic_drake.reproduce.stages.offline_real import stage_offline_real
from vic_drake.reproduce.stages.offline_sim import stage_offline_sim
from vic_drake.reproduce.stages.online import stage_online
from vic_drake.reproduce.stages.real_scans import stage_real_scans
from vic_drake.reproduce.stages.replay import stage_replay
from vic_drake.reproduce.stages.report import stage_report
from vic_drake.reproduce.stages.scans import stage_scans

#: The stages in run order; their names are
#: :data:`vic_drake.reproduce.stage_names.STAGE_NAMES`.
STAGES: tuple[tuple[str, Callable[[RunContext], Any]], ...] = (
    ("offline_real", stage_offline_real),
    ("offline_sim", stage_offline_sim),
    ("map", stage_map),
    ("real_scans", stage_real_scans),
    ("scans", stage_scans),
    ("replay", stage_replay),
    ("compare_real", stage_compare_real),
    ("online", stage_online),
    ("claims", stage_claims),
    ("report", stage_report),
)


@dataclass
class ReproduceResult:
    """What a run produced."""

    out_dir: Path
    claims: dict
    records: list[StageRecord]
    wall_s: float
    report_path: Path | None
    results: dict

    @property
    def all_claims_pass(self) -> bool:
        """True when there are claims and every one passed."""
        return bool(self.claims) and all(
            claim_status(c) == PASS for c in self.claims.values()
        )

    def summary(self) -> dict:
        return {
            "out_dir": str(self.out_dir),
            "report": str(self.report_path) if self.report_path else None,
            "wall_s": round(self.wall_s, 1),
            "stages": [r.as_dict() for r in self.records],
            "claims": {k: claim_status(v) for k, v in self.claims.items()},
            "all_claims_pass": self.all_claims_pass,
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
            rec = StageRecord(
                name, False, time.perf_counter() - t0, f"skipped: {exc}", skipped=True
            )
            ctx.progress(f"[{i + 1}/{len(names)}] {name} skipped: {exc}")
        except Exception as exc:  # noqa: BLE001 - a failed stage is reported, not fatal
            if interrupted():  # Ctrl-C that came back wrapped in another error.
                raise KeyboardInterrupt from exc
            msg = f"{type(exc).__name__}: {exc}"
            rec = StageRecord(name, False, time.perf_counter() - t0, msg)
            ctx.progress(f"[{i + 1}/{len(names)}] {name} FAILED: {msg}")
            log = ctx.out_dir / "logs" / "errors.txt"
            log.parent.mkdir(parents=True, exist_ok=True)
            with log.open("a", encoding="utf-8") as fh:
                fh.write(f"--- stage {name}\n{traceback.format_exc()}\n")
        ctx.records.append(rec)
        if interrupted():  # Ctrl-C that a library swallowed.
            raise KeyboardInterrupt


#: The stages that run on Dask (``options.workers`` / ``options.scheduler``).
CLUSTER_STAGES = ("scans", "compare_real")


def reproduce(options: ReproduceOptions) -> ReproduceResult:
    """Runs the reproduction; returns the claims and where everything is.

    The outputs are written through a work folder and moved to
    ``options.out_dir`` only when every selected stage has run
    (:mod:`vic_drake.reproduce.run_dir`); an interrupted run leaves the
    previous run in ``out_dir`` whole. A previous complete run there is
    replaced only by a run that covers it (every stage that ran there, the
    data if it had it) or with ``options.overwrite``.

    Raises:
        VicDrakeError: the output folder cannot be used, or holds a complete
            run that this one does not cover, or ``options.scheduler`` does
            not answer (checked before any work).
    """
    data_dir = find_data_dir(options.data_dir)
    if options.scheduler and (
        options.stages is None or set(options.stages) & set(CLUSTER_STAGES)
    ):
        # Function-local: distributed (heavy).
        from vic_drake.experiments.dask_cluster import check_scheduler

        check_scheduler(options.scheduler)
    work = prepare_run_dir(
        options.out_dir,
        stages=options.stages,
        data_dir=data_dir,
        overwrite=options.overwrite,
        quick=options.quick,
    )
    ctx = RunContext(options, work_dir=work)
    t0 = time.perf_counter()
    try:
        with sigint_watch():
            run_pipeline(ctx)
    except BaseException:
        options.progress(
            f"run stopped; its partial outputs are in {str(work)!r}, marked "
            f"incomplete ({RUN_FILE}); {str(options.out_dir)!r} is unchanged"
        )
        raise
    wall = time.perf_counter() - t0
    claims = (ctx.results.get("claims") or {}).get("claims", {})
    out = finish_run_dir(
        work,
        options.out_dir,
        wall_s=round(wall, 2),
        quick=options.quick,
        data_dir=None if data_dir is None else str(data_dir),
        stages=[r.as_dict() for r in ctx.records],
        claims={k: claim_status(v) for k, v in claims.items()},
    )
    for value in ctx.results.values():  # Paths into the work folder -> out.
        if isinstance(value, dict) and isinstance(value.get("path"), Path):
            value["path"] = out / value["path"].relative_to(work)
    report = (ctx.results.get("report") or {}).get("path")
    return ReproduceResult(out, claims, ctx.records, wall, report, ctx.results)
