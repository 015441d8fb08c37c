"""``vic-drake reproduce``: the paper end to end (see vic_drake.reproduce)."""

from __future__ import annotations

import argparse

from vic_drake.commands.common import (
    Progress,
    add_data_dir_option,
    add_json_option,
    emit,
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
    )
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    parser.add_argument(
        "--quick",
        action="store_true",
        help="shorter scans and a coarser map (under 5 minutes on 2 cores)",
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
        help="comma-separated stages to run (default: all)",
    )
    add_data_dir_option(parser)
    add_json_option(parser)
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")
    parser.set_defaults(handler=_run)


def _run(args: argparse.Namespace) -> int:
    from vic_drake.reproduce import ReproduceOptions, reproduce

    stages = None
    if args.stages:
        stages = tuple(s.strip() for s in args.stages.split(",") if s.strip())
    options = ReproduceOptions(
        out_dir=args.out,
        data_dir=args.data_dir,
        quick=args.quick,
        phantom=args.phantom,
        stages=stages,
        progress=Progress(enabled=not (args.quiet or args.json)),
    )
    result = reproduce(options)
    summary = result.summary()
    lines = [f"wall time {result.wall_s:.1f} s"]
    for cid, c in result.claims.items():
        lines.append(f"  {cid}: {'PASS' if c['pass'] else 'FAIL'}  {c['statement']}")
    failed = [r for r in result.records if not r.ok]
    for r in failed:
        lines.append(f"  stage {r.name}: {r.error}")
    if result.report_path:
        lines.append(f"report: {result.report_path}")
    emit(summary, args.json, "\n".join(lines))
    return 0
