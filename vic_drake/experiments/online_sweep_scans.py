"""The scans of a closed-loop comparison sweep, and their run on Dask.

:func:`sweep_scans` lists a sweep's scans; :class:`ComparisonScan` is one
as plain data, which a Dask worker turns into scores by building its own
Diagram in a process of its own (:func:`comparison_scan_in_child`);
:func:`run_on_cluster` makes them all on a local cluster or on an existing
scheduler (:mod:`vic_drake.experiments.dask_cluster`).
"""

from __future__ import annotations

import dataclasses

from vic_drake.errors import VicDrakeError


def sweep_scans(runs, dither_hzs) -> list[tuple[str, float | None]]:
    """The scans of a sweep, in order: (run, hz) for each dithered run at
    each frequency, (run, None) once for a run without the dither."""
    from vic_drake.experiments.online_compare import COMPARISON_RUNS

    return [
        (run, hz)
        for run in runs
        for hz in (tuple(dither_hzs) if COMPARISON_RUNS[run].dither else (None,))
    ]


@dataclasses.dataclass(frozen=True)
class ComparisonScan:
    """One scan of a sweep as plain data, for a worker (Diagrams do not
    pickle; the worker builds its own from the scenario's YAML)."""

    scenario_yaml: str
    phantom: object
    run: str
    dither_hz: float | None  # None: a run without the dither
    duration_s: float | None


def comparison_scan(scan: ComparisonScan) -> dict:
    """The scores of one scan of a sweep (in the calling process)."""
    from vic_drake.experiments import online_compare
    from vic_drake.scenario import loads_scenario

    hz = online_compare.DITHER_HZ if scan.dither_hz is None else scan.dither_hz
    return online_compare.online_comparison(
        loads_scenario(scan.scenario_yaml),
        phantom=scan.phantom,
        runs=(scan.run,),
        duration_s=scan.duration_s,
        progress=None,
        dither_hz=hz,
    )[scan.run]


def comparison_scan_in_child(scan: ComparisonScan) -> tuple[dict | None, str | None]:
    """(scores, None), or (None, why the scan failed): :func:`comparison_scan`
    in a process of its own, what a Dask worker runs
    (:func:`~vic_drake.experiments.child_process.run_in_child`: a worker
    does not grow by each scan's Diagram). A failure is returned, not
    raised, so that the worker does not log its traceback."""
    from vic_drake.experiments.child_process import ChildFailed, run_in_child

    try:
        return run_in_child(comparison_scan, scan), None
    except (ChildFailed, ValueError) as exc:  # ValueError: VIC_DRAKE_ALLOCATOR.
        return None, str(exc)


def run_on_cluster(jobs, workers, scheduler, on_scan=None) -> list[dict]:
    """The scores of each :class:`ComparisonScan` in ``jobs`` (in order), each
    made by :func:`comparison_scan_in_child` on a Dask cluster
    (:func:`~vic_drake.experiments.dask_cluster.map_on_cluster`).

    Raises:
        VicDrakeError: the cluster cannot be had, or a scan failed (which,
            and why; the scans still to run are cancelled).
        KeyboardInterrupt: on Ctrl-C, once the cluster is closed.
    """
    from vic_drake.experiments.dask_cluster import map_on_cluster

    def describe(i: int) -> str:
        job = jobs[i]
        at = "" if job.dither_hz is None else f" at {job.dither_hz:g} Hz"
        return f"the scan {job.run}{at}"

    def done(i: int, result, _count: int) -> None:
        why = result[1]
        if why is not None:
            raise VicDrakeError(f"{describe(i)} failed: {why}")
        if on_scan is not None:
            on_scan(jobs[i].run, jobs[i].dither_hz)

    results = map_on_cluster(
        comparison_scan_in_child,
        jobs,
        workers,
        scheduler,
        name="compare-online",
        describe=describe,
        on_done=done,
    )
    return [scores for scores, _ in results]


__all__ = [
    "ComparisonScan",
    "comparison_scan",
    "comparison_scan_in_child",
    "run_on_cluster",
    "sweep_scans",
]
