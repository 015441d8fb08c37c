"""``vic-drake reproduce``: the paper end to end (see vic_drake.reproduce)."""

from __future__ import annotations

import argparse
import sys
import time

from vic_drake.commands.common import (
    Progress,
    add_data_dir_option,
    add_json_option,
    emit,
    parse_relaxation,
)
from vic_drake.experiments.dask_cluster import add_cluster_arguments
from vic_drake.reproduce.stage_names import STAGE_NAMES

#: Exit statuses of ``vic-drake reproduce`` (documented in its --help).
EXIT_ALL_PASS, EXIT_CLAIMS_NOT_ALL_PASS = 0, 1

_EPILOG = (
    "exit status: 0 when every claim C1-C7 passed; 1 when a claim failed or was "
    "not evaluated (e.g. a stage failed or was not selected with --stages), unless "
    "--allow-fail; 2 on bad input (nothing is simulated); 130 when interrupted "
    "(Ctrl-C). Outputs are written to a work folder beside OUT and moved to OUT "
    'only when the run finishes; OUT/run.json says "complete": true. A previous '
    "run in OUT is replaced only by a run that covers it (every stage that ran "
    "there, and the data if it had it), else with --overwrite."
)


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "reproduce",
        help="reproduce the paper: offline fits, maps, scans, disturbance, claims, report",
        description=(
            "Runs the offline phase (Table I, Fig. 2-5 analogues), the scans with the four "
            "controllers nominal and with the phantom lifted, evaluates the claims C1-C7 "
            "and writes OUT/report.html, OUT/claims.json, OUT/logs/ and OUT/replay.html."
        ),
        epilog=_EPILOG,
    )
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    parser.add_argument(
        "--quick",
        action="store_true",
        help="shorter scans and a coarser map (about half a minute on a 2-core "
        "machine, longer when it is busy)",
    )
    parser.add_argument(
        "--phantom",
        choices=("auto", "measured", "synthetic"),
        default="auto",
        help="phantom of the simulated scans (auto: the measured map when the data is "
        "there, else the synthetic chest)",
    )
    parser.add_argument(
        "--stages",
        default=None,
        metavar="LIST",
        help="comma-separated stages to run, of: "
        f"{', '.join(STAGE_NAMES)} (default: all; they run in this order)",
    )
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the previous run in OUT even when this run does not cover "
        "it (a --stages subset, or no data where it had the data); never a folder "
        "that is not a run",
    )
    parser.add_argument(
        "--allow-fail",
        action="store_true",
        help="exit 0 even when a claim failed or was not evaluated",
    )
    parser.add_argument(
        "--meshcat",
        action="store_true",
        help="after the run, serve the replay live in Meshcat (prints its URL) until "
        "Ctrl-C",
    )
    parser.add_argument(
        "--relaxation",
        metavar="G:TAU[,G:TAU...]",
        default=None,
        help="branches of the relaxing tissue (fraction g, time constant tau in s) in "
        "every simulation of the run (default: vic_drake.tissue.DEFAULT_RELAXATION, "
        "0.08:22.9)",
    )
    add_cluster_arguments(parser, "the scans and the compare-real re-runs")
    add_data_dir_option(parser)
    add_json_option(parser)
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")
    parser.set_defaults(handler=_run)


def _claim_line(cid: str, claim: dict) -> str:
    from vic_drake.analysis.claims import FAIL, NOT_EVALUATED, claim_status
    from vic_drake.analysis.claims.reasons import fail_reasons

    status = claim_status(claim)
    line = f"  {cid}: {status.upper():<13} {claim['statement']}"
    if status == NOT_EVALUATED:
        reasons = [
            p.strip()
            for p in (claim.get("detail") or "").split(";")
            if "not evaluated" in p
        ]
        line += f"\n      ({'; '.join(reasons) or 'no reason recorded'})"
    elif status == FAIL:
        for reason in fail_reasons(cid, claim) or ["no reason recorded"]:
            line += f"\n      ({reason})"
    return line


def _serve_live(result, say) -> None:
    """Keeps the replay's Meshcat server open until Ctrl-C."""
    meshcat = (result.results.get("replay") or {}).get("meshcat")
    if meshcat is None:
        say("--meshcat: no replay was made in this run (the replay stage did not run)")
        return
    print(
        f"Meshcat replay live at {meshcat.web_url()} (press Ctrl-C to stop)",
        file=sys.stderr,
        flush=True,
    )
    try:
        while True:
            time.sleep(0.5)
    except KeyboardInterrupt:
        print("Meshcat stopped", file=sys.stderr, flush=True)


def _run(args: argparse.Namespace) -> int:
    from vic_drake.reproduce import ReproduceOptions, reproduce

    stages = None
    if args.stages is not None:  # An empty list is an error (options).
        stages = tuple(s.strip() for s in args.stages.split(",") if s.strip())
    progress = Progress(enabled=not (args.quiet or args.json))
    options = ReproduceOptions(
        out_dir=args.out,
        data_dir=args.data_dir,
        quick=args.quick,
        phantom=args.phantom,
        stages=stages,
        meshcat=args.meshcat,
        overwrite=args.overwrite,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=progress,
        relaxation=None
        if args.relaxation is None
        else parse_relaxation(args.relaxation),
    )
    result = reproduce(options)
    summary = result.summary()
    lines = [f"wall time {result.wall_s:.1f} s"]
    for cid, c in result.claims.items():
        lines.append(_claim_line(cid, c))
    counts = {}
    for status in summary["claims"].values():
        counts[status] = counts.get(status, 0) + 1
    if counts:
        lines.append(
            "claims: " + ", ".join(f"{n} {status}" for status, n in counts.items())
        )
    failed = [r for r in result.records if not r.ok]
    for r in failed:
        lines.append(f"  stage {r.name}: {r.error}")
    if result.report_path:
        lines.append(f"report: {result.report_path}")
    emit(summary, args.json, "\n".join(lines))
    if args.meshcat:
        _serve_live(result, progress)
    if result.all_claims_pass or args.allow_fail:
        return EXIT_ALL_PASS
    return EXIT_CLAIMS_NOT_ALL_PASS
