"""The campaign engine: runs on a Dask cluster, rows on disk, resume.

:func:`run_campaign` plans every run (checking every scenario before any
starts), then submits the runs still to do to a Dask cluster: a
``LocalCluster`` of worker processes, or an existing scheduler by address
(started with ``dask scheduler`` / ``dask worker``). Workers execute
:func:`vic_drake.experiments.campaign.run.execute_run` and return plain rows.

The output folder::

    spec.yaml             the campaign spec (a resume must match it)
    base_scenario.yaml    its base scenario file (a resume must match it)
    scenarios/RUN.yaml    each finished run's exact scenario (vic-drake scan RUN.yaml)
    rows/RUN.json         each finished run's row, written atomically
    results.parquet       every row (written at the end)
    summary.json, summary.html

``--out`` may be new or empty, or with ``resume`` this campaign's folder
(a resume into a new or empty one says so and starts); a folder holding
anything else, such as a reproduce run, is refused before any work. The
folder is made once the cluster is reached, so a campaign that cannot
start leaves nothing behind.

A worker that dies loses its current run; the scheduler gives that run to
another worker once (``distributed.scheduler.allowed-failures`` = 1 on a
local cluster; an external scheduler uses its own setting), then the run is
recorded as failed. ``resume`` skips every run with a row, except those
that failed with an error (a lost worker, a broken node: they are run
again), and never runs one twice.

Each row carries the ``code_id`` (:func:`vic_drake.provenance.code_id`) of
the process that computed it. A resume whose code differs from the stored
rows' is refused unless ``allow_code_change`` (the summary then counts the
rows per code). Workers whose code differs from this process's are refused
when the cluster is reached (:func:`~vic_drake.experiments.dask_cluster.dask_session`).

Ctrl-C stops the campaign: the local workers ignore it (the runs' own
processes stop on it), the campaign closes the cluster with Dask's
warnings hidden, says how many runs are kept and the command that finishes
the rest, and raises KeyboardInterrupt. While the local cluster starts,
Ctrl-C is held back (its worker processes start with it blocked) and taken
once the cluster is up: the cluster is closed and nothing is written.
"""

from __future__ import annotations

import difflib
import json
import os
import shlex
import time
from collections.abc import Callable
from pathlib import Path

import pandas as pd

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign.plan import RunPlan, plan_campaign
from vic_drake.experiments.campaign.run import METRIC_KEYS, failed_row
from vic_drake.experiments.campaign.spec import CampaignSpec, load_campaign_spec
from vic_drake.experiments.campaign.stats import paired_arms, per_controller
from vic_drake.experiments.dask_cluster import dask_session
from vic_drake.jsonio import to_json
from vic_drake.paper import CONTACT_THRESHOLD_N
from vic_drake.paths import (
    CAMPAIGN_SCENARIOS_DIR,
    CAMPAIGN_SPEC_FILE,
    check_run_folder,
)
from vic_drake.provenance import code_id
from vic_drake.scenario import dumps_scenario, load_scenario

#: The campaign's base scenario file as it was (a resume must match it).
CAMPAIGN_BASE_FILE = "base_scenario.yaml"


def _atomic_write(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def _spec_text(spec: CampaignSpec, base: Path) -> str:
    from pydrake.common.yaml import yaml_dump_typed

    stored = CampaignSpec(**{**spec.__dict__, "base_scenario": str(base)})
    return yaml_dump_typed(stored)


def read_rows(out: Path) -> pd.DataFrame:
    """Every finished row of a campaign folder, ordered by run index."""
    rows = [
        json.loads(p.read_text()) for p in sorted((out / "rows").glob("run_*.json"))
    ]
    df = pd.DataFrame(rows)
    if df.empty:
        return df
    # The rows hold null where a figure is NaN (strict JSON).
    for key in (*METRIC_KEYS, "sim_s", "wall_s"):
        if key in df:
            df[key] = pd.to_numeric(df[key], errors="coerce")
    return df.sort_values("index").reset_index(drop=True)


def _check_out(
    out: Path,
    texts: dict,
    plans: list[RunPlan],
    resume: bool,
    emit,
    allow_code_change: bool = False,
) -> set[str]:
    """Checks ``out`` before any work, writing nothing; returns the run ids
    finished there (a run whose row says it failed with an error is not:
    a resume runs it again).

    ``out`` may be new, an empty folder, or (with ``resume``) this
    campaign's folder: the same spec and base scenario, rows computed by
    this code (or ``allow_code_change``). A folder holding anything else is
    refused, so a campaign never mixes its files into another run's folder.
    """
    own = check_run_folder(
        out, CAMPAIGN_SPEC_FILE, others="(with --resume) a campaign's own folder"
    )
    if own:
        if not resume:
            raise VicDrakeError(
                f"{str(out)!r} already holds a campaign; pass --resume to finish it "
                "or choose another --out"
            )
        _check_same(
            out / CAMPAIGN_SPEC_FILE, texts[CAMPAIGN_SPEC_FILE], "campaign spec"
        )
        if (out / CAMPAIGN_BASE_FILE).is_file():  # Folders before it: not kept.
            _check_same(
                out / CAMPAIGN_BASE_FILE, texts[CAMPAIGN_BASE_FILE], "base scenario"
            )
        planned = {p.run_id for p in plans}
        stored = {p.stem for p in (out / "rows").glob("run_*.json")} & planned
        rows = {r: _row(out, r) for r in sorted(stored)}  # Each read once.
        failed = {r for r, row in rows.items() if row.get("status") == "error"}
        done = stored - failed
        if not allow_code_change and len(done) < len(planned):
            # Runs to add: they must be the stored rows' code's. (With none
            # left, a resume only summarises the rows again.)
            kept = pd.DataFrame([rows[r] for r in sorted(done)])
            _check_stored_code(out, _code_counts(kept))
        if failed:
            emit(
                f"{len(failed)} run{'s' if len(failed) > 1 else ''} of {str(out)!r} "
                "failed with an error before: running them again"
            )
        return done
    if resume:
        # Starting is what --resume asks for in the end (every run done),
        # and nothing can be lost in a new or empty folder.
        where = "is empty" if out.is_dir() else "does not exist"
        emit(f"nothing to resume: {str(out)!r} {where}; starting the campaign")
    return set()


def _row(out: Path, run_id: str) -> dict:
    return json.loads((out / "rows" / f"{run_id}.json").read_text())


def _check_same(stored: Path, text: str, what: str) -> None:
    """Refuses a resume whose spec or base scenario is not the stored one,
    showing the first lines that differ."""
    before = stored.read_text()
    if before == text:
        return
    diff = [
        line.replace("@@ ", "").replace(" @@", ":")  # "-12 +12:" (line numbers).
        if line.startswith("@@")
        else line
        for line in difflib.unified_diff(
            before.splitlines(), text.splitlines(), lineterm="", n=0
        )
        if line[:3] not in ("+++", "---")
    ]
    shown = "; ".join(diff[:6]) + ("; ..." if len(diff) > 6 else "")
    raise VicDrakeError(
        f"{str(stored.parent)!r} holds another {what} ({stored.name}); --resume "
        f"needs the same. Stored (-) and now (+): {shown}"
    )


#: What a row written before rows carried their code shows as its code.
UNKNOWN_CODE = "unknown (a row written before rows recorded their code)"


def _check_stored_code(out: Path, counts: dict[str, int]) -> None:
    """Refuses a resume whose code is not the stored rows' (``counts``:
    :func:`_code_counts` of the rows it keeps)."""
    here = code_id()
    other = {c: n for c, n in counts.items() if c != here}
    if other:
        stored = "; ".join(f"{n} by {c}" for c, n in other.items())
        raise VicDrakeError(
            f"{str(out)!r} holds rows computed by other code ({stored}); this is "
            f"{here}. A resume would mix two codes' results in one summary: "
            "finish it with the code that began it, start again in a new --out, "
            "or pass --allow-code-change to mix them (the summary then counts "
            "the rows per code)"
        )


def _create(out: Path, texts: dict) -> None:
    """Makes the campaign's folder and writes its spec and base scenario
    (once the runs can start). A folder from before the base scenario was
    kept does not get one: its rows' base is not known."""
    new = not (out / CAMPAIGN_SPEC_FILE).is_file()
    (out / CAMPAIGN_SCENARIOS_DIR).mkdir(parents=True, exist_ok=True)
    (out / "rows").mkdir(exist_ok=True)
    for name, text in texts.items():
        if new or name == CAMPAIGN_SPEC_FILE:
            _atomic_write(out / name, text)


def _record(out: Path, plan: RunPlan, row: dict) -> None:
    """Writes a run's scenario, then its row (the row marks the run done)."""
    text = row.pop("_scenario_yaml", None)
    if text is None:  # The worker never got to build it (e.g. it died).
        text = dumps_scenario(plan.scenario())
    _atomic_write(out / CAMPAIGN_SCENARIOS_DIR / f"{plan.run_id}.yaml", text)
    _atomic_write(out / "rows" / f"{plan.run_id}.json", to_json(row, indent=None))


class _Progress:
    def __init__(self, name: str, total: int, done: int, emit: Callable[[str], None]):
        self.name, self.total, self.emit = name, total, emit
        self.done0, self.done, self.failed = done, done, 0
        self.t0 = time.perf_counter()

    def add(self, row: dict) -> None:
        self.done += 1
        self.failed += row["status"] != "ok"
        new = self.done - self.done0
        elapsed = time.perf_counter() - self.t0
        rate = new / elapsed * 3600 if elapsed > 0 else 0.0
        left = self.total - self.done
        eta = left / rate * 3600 if rate > 0 else float("nan")
        eta_text = time.strftime("%H:%M:%S", time.gmtime(eta)) if eta == eta else "?"
        self.emit(
            f"[{self.name}] {self.done}/{self.total} done, {self.failed} failed, "
            f"{left} remaining, {rate:.0f} runs/h, ETA {eta_text} "
            f"({row['run_id']}: {row['status']})"
        )


def _resume_command(spec_path, out: Path, workers, scheduler) -> str:
    """The command that finishes this campaign, for the interrupted message."""
    cmd = ["vic-drake", "campaign", str(spec_path), "--out", str(out)]
    if scheduler:
        cmd += ["--scheduler", scheduler]
    elif workers:
        cmd += ["--workers", str(workers)]
    return shlex.join([*cmd, "--resume"])


def run_campaign(
    spec_path: str | os.PathLike,
    out: str | os.PathLike,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
    max_runs: int | None = None,
    allow_code_change: bool = False,
) -> dict:
    """Runs (or finishes) a campaign; returns its JSON summary.

    Args:
        spec_path: the campaign YAML.
        out: output folder (see the module docstring).
        workers: local worker processes (default: the machine's cores).
        scheduler: address of an existing Dask scheduler (tcp://host:port).
        resume: finish the campaign already in ``out``.
        progress: callable(str) for progress lines (e.g. to stderr).
        max_runs: stop submitting after this many new runs (for an
            interrupted campaign in tests and benchmarks; None: all).
        allow_code_change: let a resume add rows of this code to rows that
            other code computed (refused otherwise).

    Returns:
        The summary of :func:`summary_dict` plus ``session_runs`` (the
        runs finished by this call; a resume's earlier ones are not
        counted), ``wall_s`` and ``runs_per_hour`` (this call's) and
        ``workers``.
    """
    if workers is not None and scheduler:
        raise VicDrakeError("give either --workers or --scheduler, not both")
    if workers is not None and (isinstance(workers, bool) or workers < 1):
        raise VicDrakeError(f"--workers must be >= 1; got {workers!r}")
    spec, base_path = load_campaign_spec(spec_path)
    plans = plan_campaign(spec, load_scenario(base_path))
    out = Path(out)
    emit = progress or (lambda _line: None)
    texts = {
        CAMPAIGN_SPEC_FILE: _spec_text(spec, base_path),
        # The file as written, not as loaded: a code change that adds a
        # field (its default in every dump) is not a change of the base.
        CAMPAIGN_BASE_FILE: Path(base_path).read_text(),
    }
    done = _check_out(out, texts, plans, resume, emit, allow_code_change)
    todo = [p for p in plans if p.run_id not in done]
    if max_runs is not None:
        todo = todo[:max_runs]
    bar = _Progress(spec.name, len(plans), len(done), emit)
    t0 = time.perf_counter()
    n_workers = 0
    if todo:
        # The folder is made once the cluster is reached (_submit): a
        # campaign that cannot start leaves nothing behind.
        hint = _resume_command(spec_path, out, workers, scheduler)
        n_workers = _submit(todo, out, texts, workers, scheduler, bar, emit, hint)
    else:
        _create(out, texts)
    wall = time.perf_counter() - t0
    rows = read_rows(out)
    summary = summary_dict(spec, rows)
    new = bar.done - bar.done0
    summary.update(
        session_runs=new,
        wall_s=wall,
        runs_per_hour=new / wall * 3600 if wall > 0 and new else 0.0,
        workers=n_workers,
    )
    from vic_drake.experiments.campaign.report import write_outputs

    write_outputs(out, spec, rows, summary)
    return summary


def _submit(
    todo, out: Path, texts: dict, workers, scheduler, bar: _Progress, emit, hint
) -> int:
    from distributed import as_completed

    from vic_drake.experiments.campaign.run import execute_run_in_child

    started = False  # A Ctrl-C while the cluster starts leaves nothing to tell.
    try:
        with dask_session(workers, scheduler) as (client, futures):
            started = True
            _create(out, texts)
            n_workers = len(client.scheduler_info()["workers"])
            emit(
                f"[{bar.name}] {len(todo)} runs on {n_workers} Dask workers "
                f"({client.scheduler.address})"
            )
            for plan in todo:
                fut = client.submit(
                    execute_run_in_child,
                    plan,
                    pure=False,
                    key=f"{bar.name}-{plan.run_id}-{time.time_ns()}",
                )
                futures[fut] = plan
            for fut in as_completed(list(futures)):
                plan = futures[fut]
                try:
                    row = fut.result()
                except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker after the retry.
                    row = failed_row(plan, f"{type(exc).__name__}: {exc}")
                _record(out, plan, row)
                bar.add(row)
            return n_workers
    except KeyboardInterrupt:
        if not started:
            raise
        # The cluster is closed by now.
        kept = len(list((out / "rows").glob("run_*.json")))
        emit(
            f"[{bar.name}] interrupted: {kept} of {bar.total} runs done, kept "
            f"in {str(out)!r}; finish the campaign with: {hint}"
        )
        raise


def summary_dict(spec: CampaignSpec, rows: pd.DataFrame) -> dict:
    """runs, finished, failed, nan_runs, the force limit and the contact
    threshold (N) the statistics use, and per_controller of a campaign's
    rows; with ``paired``, also paired (:func:`~.stats.paired_arms`)."""
    status = rows["status"] if not rows.empty else pd.Series([], dtype=str)
    summary = {
        "runs": spec.runs,
        "finished": int(len(rows)),
        # Failed: raised or produced NaN (nan_runs counts the latter alone).
        "failed": int((status != "ok").sum()),
        "nan_runs": int((status == "nan").sum()),
        "force_limit_N": spec.force_limit_N,
        "contact_threshold_N": CONTACT_THRESHOLD_N,
        "per_controller": per_controller(rows, spec.force_limit_N),
        "code_ids": _code_counts(rows),
    }
    if spec.paired:
        summary["paired"] = paired_arms(rows, spec.grid_size, spec.force_limit_N)
    return summary


def _code_counts(rows: pd.DataFrame) -> dict[str, int]:
    """{code_id: rows}: more than one key when a resume mixed codes."""
    if rows.empty:
        return {}
    codes = rows.get("code_id", pd.Series(UNKNOWN_CODE, index=rows.index))
    codes = codes.fillna(UNKNOWN_CODE).replace("", UNKNOWN_CODE)
    return {str(c): int(n) for c, n in codes.value_counts().items()}


__all__ = ["UNKNOWN_CODE", "read_rows", "run_campaign", "summary_dict"]
