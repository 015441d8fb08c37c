"""The closed-loop comparison over dither frequencies, and its command line.

A closed loop with an estimator in it moves by 0.1-0.2 N of force RMSE from
one dither frequency to the next (docs/decisions.md, "The comparison over
dither frequencies"), so one run's margin over another is no evidence.
:func:`online_comparison_sweep` makes every dithered run of
:data:`~vic_drake.experiments.online_compare.COMPARISON_RUNS` at each of
several frequencies (a run without the dither once);
:func:`~vic_drake.experiments.online_compare.comparison_table` shows each
score's mean and range, and :func:`sweep_wins` counts the frequencies at
which each run is below another. Its scans run one after another in this
process, or at once on a Dask cluster
(:mod:`vic_drake.experiments.online_sweep_scans`), each in a process of
its own; the command line takes the cluster for more than one scan.

The command line (``vic-drake compare-online``, or ``python -m
vic_drake.experiments.online_compare``) checks every option before a scan
(:func:`add_comparison_arguments`, :func:`prepare_comparison`). This module
imports the simulation only when a comparison runs, so the command line's
parser can be built from it at once.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.dask_cluster import add_cluster_arguments
from vic_drake.experiments.online_sweep_scans import (
    ComparisonScan,
    run_on_cluster,
    sweep_scans,
)
from vic_drake.paths import scenario_path
from vic_drake.run_limits import check_scan_duration

#: The scores :func:`sweep_wins` compares (lower is better).
WIN_SCORES = ("force_rmse_true_N", "rib_p99_force_N")


def online_comparison_sweep(
    base,
    *,
    phantom,
    runs,
    dither_hzs=None,
    duration_s=None,
    progress=None,
    on_scan=None,
    workers=None,
    scheduler=None,
) -> dict[str, list[dict]]:
    """{run: [scores at each of ``dither_hzs``]}: each dithered run made at
    every frequency (default: the comparison's DITHER_HZ alone); a run
    without the dither (which the frequency does not touch) made once, its
    scores standing at every frequency.

    The scans run one after another in this process, or, with ``workers``
    or ``scheduler``, at once on a Dask cluster
    (:func:`~vic_drake.experiments.online_sweep_scans.run_on_cluster`):
    a local one of ``workers`` processes, or the scheduler at that address.

    ``on_scan(run, hz)`` (optional) is called before each scan in this
    process, and as each scan ends on a cluster (hz None for a run without
    the dither). ``progress`` reaches the scans made in this process only.
    """
    from vic_drake.experiments import online_compare

    dither_hzs = (online_compare.DITHER_HZ,) if dither_hzs is None else dither_hzs
    scans = sweep_scans(runs, dither_hzs)
    if workers is not None or scheduler is not None:
        from vic_drake.scenario import dumps_scenario

        text = dumps_scenario(base)
        jobs = [ComparisonScan(text, phantom, run, hz, duration_s) for run, hz in scans]
        scores = run_on_cluster(jobs, workers, scheduler, on_scan)
    else:
        scores = []
        for run, hz in scans:
            if on_scan is not None:
                on_scan(run, hz)
            scores.append(
                online_compare.online_comparison(
                    base,
                    phantom=phantom,
                    runs=(run,),
                    duration_s=duration_s,
                    progress=progress,
                    dither_hz=online_compare.DITHER_HZ if hz is None else hz,
                )[run]
            )
    out = {}
    for (run, hz), one in zip(scans, scores, strict=True):
        out.setdefault(run, []).append(one)
        if hz is None:
            out[run] *= len(dither_hzs)
    return out


def sweep_wins(sweep: dict[str, list[dict]], against: str) -> dict[str, dict]:
    """For each run but ``against``: {score: at how many frequencies the run
    is strictly below ``against``} for :data:`WIN_SCORES` (a NaN on either
    side is not a win), and "of": the number of frequencies."""
    reference = sweep[against]
    wins = {}
    for run, scores in sweep.items():
        if run == against:
            continue
        row = {
            key: sum(
                bool(mine[key] < ref[key])
                for mine, ref in zip(scores, reference, strict=True)
            )
            for key in WIN_SCORES
        }
        row["of"] = len(reference)
        wins[run] = row
    return wins


def wins_table(wins: dict[str, dict], against: str, dither_hzs) -> str:
    """:func:`sweep_wins` as a markdown table."""
    hz = ", ".join(f"{f:g}" for f in dither_hzs)
    lines = [
        f"Below {against} (lower is better), of {len(dither_hzs)} dither "
        f"frequencies ({hz} Hz):",
        "",
        "| run | force RMSE vs truth | p99 force on ribs |",
        "|---|---|---|",
    ]
    for run, row in wins.items():
        lines.append(
            f"| {run} | {row['force_rmse_true_N']} of {row['of']} | "
            f"{row['rib_p99_force_N']} of {row['of']} |"
        )
    return "\n".join(lines)


def comparison_report(sweep: dict[str, list[dict]], dither_hzs, against) -> str:
    """What the command prints: the table (of means and ranges over several
    frequencies) and, with ``against``, :func:`wins_table`."""
    from vic_drake.experiments.online_compare import COLUMN_LEGEND, comparison_table

    if len(dither_hzs) == 1:
        text = comparison_table({run: scores[0] for run, scores in sweep.items()})
    else:
        hz = ", ".join(f"{f:g}" for f in dither_hzs)
        text = (
            f"Mean (min-max) over the dither frequencies {hz} Hz:\n\n"
            + comparison_table(sweep)
        )
    text += "\n\n" + "\n".join(f"- {line}" for line in COLUMN_LEGEND)
    notes = _nan_notes(sweep)
    if notes:
        text += "\n\n" + "\n".join(notes)
    if against is not None:
        text += "\n\n" + wins_table(sweep_wins(sweep, against), against, dither_hzs)
    return text


def _nan_notes(sweep: dict[str, list[dict]]) -> list[str]:
    """Why a run's force RMSE or rib p99 is nan, for each run where it is."""
    from vic_drake.analysis.scan_metrics import RIB_KAPPA_THRESHOLD

    def runs_with_nan(key):
        return [
            run
            for run, scores in sweep.items()
            if any(not math.isfinite(one[key]) for one in scores)
        ]

    notes = []
    if no_window := runs_with_nan("force_rmse_true_N"):
        notes.append(
            f"nan scores ({', '.join(no_window)}): no scan window in what was "
            "simulated (the window starts 1 s after the first contact and ends at "
            "the final lift); a longer --duration, or none, gives one."
        )
    if no_rib := runs_with_nan("rib_p99_force_N"):
        notes.append(
            f"nan p99 force on ribs ({', '.join(no_rib)}): the scan window passed "
            f"over no rib (true kappa above {RIB_KAPPA_THRESHOLD:g} N/m^beta)."
        )
    return notes


def sweep_json(sweep: dict[str, list[dict]], dither_hzs, against) -> dict:
    """The command's ``--json``: {"dither_hz", "scores": {run: [scores at
    each frequency]}, "against", "wins"} (wins None without ``against``)."""
    return {
        "dither_hz": list(dither_hzs),
        "scores": sweep,
        "against": against,
        "wins": None if against is None else sweep_wins(sweep, against),
    }


def add_comparison_arguments(parser: argparse.ArgumentParser) -> None:
    """The comparison's arguments: SCENARIO, RUN ..., --dither-hz,
    --force-min-z, --against, --duration, --workers | --scheduler."""
    parser.add_argument(
        "scenario",
        metavar="SCENARIO",
        help="a VS-VF scenario YAML, or the name of a shipped one "
        "(e.g. nominal_vs_vf_synthetic)",
    )
    parser.add_argument(
        "runs",
        nargs="*",
        metavar="RUN",
        help="runs to make (default: all; e.g. true_map_dither "
        "wrong_map_+30_dither online_dither_tracker; a wrong name lists them)",
    )
    parser.add_argument(
        "--dither-hz",
        type=float,
        nargs="+",
        default=None,
        metavar="HZ",
        help="frequencies of the dithered runs' dither, Hz: each dithered run is "
        "made at each (default 3.0; the online fit was measured at 2.9-3.1 Hz and "
        "is noisier at 4-6 Hz: README, 'Online estimation in closed loop')",
    )
    parser.add_argument(
        "--force-min-z",
        type=float,
        default=None,
        metavar="N",
        help="VS-VF's F_min,z of every run, N (sensor convention, < 0; default: "
        "the scenario's)",
    )
    parser.add_argument(
        "--against",
        default=None,
        metavar="RUN",
        help="also count, per run, the frequencies at which its force RMSE and "
        "its p99 force on the ribs are below RUN's (RUN is made if not listed)",
    )
    parser.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="S",
        help="simulate only the first S seconds of each scan (default: the whole "
        "scan; the scores cover what was simulated)",
    )
    add_cluster_arguments(
        parser, "the scans", "; a comparison of one scan runs in this process"
    )


def prepare_comparison(args: argparse.Namespace, say=None):
    """(base scenario, runs, phantom) of the parsed arguments, every option
    checked before a scan; ``args.dither_hz`` None becomes [DITHER_HZ].

    Args:
        args: from a parser with :func:`add_comparison_arguments`.
        say: reports a bare scenario name read as a shipped scenario
            (:func:`vic_drake.paths.scenario_path`).

    Raises:
        VicDrakeError: naming the option that is wrong and what it takes.
    """
    from vic_drake.experiments.online_compare import (
        COMPARISON_RUNS,
        DITHER_HZ,
        comparison_scenario,
    )
    from vic_drake.experiments.scan_diagram import load_scenario_phantom
    from vic_drake.scenario import load_scenario

    if args.dither_hz is None:
        args.dither_hz = [DITHER_HZ]
    unknown = [r for r in args.runs if r not in COMPARISON_RUNS]
    if args.against is not None and args.against not in COMPARISON_RUNS:
        unknown.append(args.against)
    if unknown:
        raise VicDrakeError(
            f"unknown runs {unknown}; choose from {list(COMPARISON_RUNS)}"
        )
    twice = sorted({hz for hz in args.dither_hz if args.dither_hz.count(hz) > 1})
    if twice:
        raise VicDrakeError(
            f"--dither-hz {' '.join(f'{hz:g}' for hz in args.dither_hz)}: "
            f"{', '.join(f'{hz:g}' for hz in twice)} Hz given twice; give each "
            "frequency once"
        )
    if args.duration is not None and not (
        math.isfinite(args.duration) and args.duration > 0.0
    ):
        raise VicDrakeError(f"--duration must be > 0 s; got {args.duration!r}")
    base = load_scenario(scenario_path(args.scenario, say))
    kind = base.controller.reference.controller
    if kind != "vs-vf":
        raise VicDrakeError(
            f"scenario {args.scenario!r} runs controller {kind!r}; the comparison "
            "needs a VS-VF scenario (controller 'vs-vf': it scores VS-VF's force "
            "reference, made from kappa), e.g. nominal_vs_vf_synthetic or "
            "real_test_nardi_matForce_lowR"
        )
    if args.duration is not None:
        check_scan_duration(base, args.duration)
    if args.force_min_z is not None:
        base.controller.reference.force_min_z_N = args.force_min_z
        try:
            base = base.validate()
        except VicDrakeError as exc:
            raise VicDrakeError(f"--force-min-z {args.force_min_z!r}: {exc}") from None
    runs = tuple(args.runs) or tuple(COMPARISON_RUNS)
    if args.against is not None and args.against not in runs:
        runs += (args.against,)
    for hz in args.dither_hz:  # Every frequency (even if no run is dithered).
        try:
            comparison_scenario(base, "online_dither", dither_hz=hz)
        except VicDrakeError as exc:
            raise VicDrakeError(f"--dither-hz {hz!r}: {exc}") from None
    return base, runs, load_scenario_phantom(base)


def scan_progress(runs, dither_hzs, say=None, *, ended=False):
    """An ``on_scan`` for :func:`online_comparison_sweep` that says "scan k
    of n: RUN at HZ (t s so far)" (with ``ended``, as on a cluster: "scan k
    of n done: ...") through ``say`` (default: stderr), when there is more
    than one scan."""
    total = len(sweep_scans(runs, dither_hzs))
    say = say or (lambda text: print(text, file=sys.stderr, flush=True))
    done = " done" if ended else ""
    t0, made = time.perf_counter(), 0

    def on_scan(run, hz):
        nonlocal made
        made += 1
        if total > 1:
            at = "" if hz is None else f" at {hz:g} Hz"
            elapsed = time.perf_counter() - t0
            say(f"scan {made} of {total}{done}: {run}{at} ({elapsed:.0f} s so far)")

    return on_scan


def run_comparison(args: argparse.Namespace, say=None) -> dict[str, list[dict]]:
    """The comparison the parsed arguments ask for: every option checked
    (:func:`prepare_comparison`, before any scan), then
    :func:`online_comparison_sweep` with a line per scan through ``say``
    (default: stderr). More than one scan, or ``--scheduler``, runs on a
    Dask cluster (a local one of ``--workers`` processes, default the
    machine's cores); a single scan runs in this process."""
    say = say or (lambda text: print(text, file=sys.stderr, flush=True))
    base, runs, phantom = prepare_comparison(args, say)
    workers, scheduler = args.workers, args.scheduler
    n_scans = len(sweep_scans(runs, args.dither_hz))
    on_cluster = scheduler is not None or n_scans > 1
    if on_cluster and scheduler is None and workers is None:
        workers = os.cpu_count() or 1
    if on_cluster:
        where = scheduler or (
            f"a local cluster of {workers} worker process"
            + ("" if workers == 1 else "es")
        )
        say(f"{n_scans} scans on {where}")
    return online_comparison_sweep(
        base,
        phantom=phantom,
        runs=runs,
        dither_hzs=args.dither_hz,
        duration_s=args.duration,
        on_scan=scan_progress(runs, args.dither_hz, say, ended=on_cluster),
        workers=workers if on_cluster else None,
        scheduler=scheduler,
    )


def main(argv=None) -> None:
    """``python -m vic_drake.experiments.online_compare SCENARIO [RUN ...]
    [--dither-hz HZ [HZ ...]] [--force-min-z N] [--against RUN] [--duration
    S]``, as ``vic-drake compare-online`` without ``--json``: prints the
    table and, with ``--against``, at how many frequencies each run is below
    RUN."""
    parser = argparse.ArgumentParser(description=main.__doc__.replace("``", ""))
    add_comparison_arguments(parser)
    args = parser.parse_args(argv)
    try:
        sweep = run_comparison(args)
    except VicDrakeError as exc:
        parser.error(str(exc))
    print(comparison_report(sweep, args.dither_hz, args.against))


__all__ = [
    "WIN_SCORES",
    "add_comparison_arguments",
    "comparison_report",
    "main",
    "online_comparison_sweep",
    "prepare_comparison",
    "run_comparison",
    "scan_progress",
    "sweep_json",
    "sweep_wins",
    "wins_table",
]
