"""Wall time of ``vic-drake reproduce`` per stage (quick mode by default).

Goals (issue): --quick under 5 minutes on a 2-core machine, the full run
under 30 minutes. Prints the stage times and the total; no asserts.

With ``--baseline DIR`` (another checkout) each round runs both checkouts'
``vic-drake reproduce`` in processes of their own, alternated, so that a
busy host weighs on both alike; it prints each run's stage times and peak
memory (the run's process and its workers).

Usage:
    python benchmarks/bench_reproduce.py [--full] [--out DIR]
    python benchmarks/bench_reproduce.py --baseline DIR [--stages scans]
        [--rounds 2] [--full]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time

from common import HERE, is_checkout, run_timed, versions


def _in_process(args) -> None:
    from vic_drake.analysis.claims import claim_status
    from vic_drake.reproduce import ReproduceOptions, reproduce

    out = args.out or tempfile.mkdtemp(prefix="vic_drake_bench_")
    t0 = time.perf_counter()
    result = reproduce(ReproduceOptions(out_dir=out, quick=not args.full))
    total = time.perf_counter() - t0
    goal = 30 * 60 if args.full else 5 * 60
    print(
        f"mode: {'full' if args.full else 'quick'}; {os.cpu_count()} CPUs; output {out}"
    )
    for r in result.records:
        status = "ok" if r.ok else f"FAILED ({r.error})"
        print(f"  {r.name:<13} {r.wall_s:8.1f} s  {status}")
    print(
        f"total {total:.1f} s (goal < {goal} s: {'met' if total < goal else 'NOT met'})"
    )
    print(
        "claims: "
        + ", ".join(f"{k} {claim_status(v).upper()}" for k, v in result.claims.items())
    )


def _one_run(tree: str, args, out: str) -> tuple[dict, float, float]:
    """(the run's --json summary, wall s, peak RSS of its largest process,
    MB, its Dask workers included: :func:`common.run_timed`)."""
    command = [sys.executable, "-m", "vic_drake.cli", "reproduce", "--out", out]
    command += ["--json", "--allow-fail", "--overwrite"]
    command += [] if args.full else ["--quick"]
    command += ["--stages", args.stages] if args.stages else []
    command += ["--phantom", args.phantom]
    out_text, wall, peak = run_timed(tree, command)
    return json.loads(out_text), wall, peak


def _interleaved(args) -> None:
    trees = {"baseline": os.path.abspath(args.baseline), "this": HERE}
    print(
        f"{os.cpu_count()} CPUs; {args.rounds} rounds, alternated; phantom {args.phantom}"
    )
    for k, tree in trees.items():
        print(f"  {k}: {tree}")
    with tempfile.TemporaryDirectory(prefix="vic_drake_bench_") as tmp:
        for round_ in range(args.rounds):
            order = list(trees) if round_ % 2 == 0 else list(trees)[::-1]
            for k in order:
                summary, wall, peak = _one_run(trees[k], args, f"{tmp}/{k}")
                stages = ", ".join(
                    f"{s['name']} {s['wall_s']:.1f} s" for s in summary["stages"]
                )
                print(
                    f"round {round_ + 1} {k:<8} wall {wall:6.1f} s  [{stages}]  "
                    f"peak RSS {peak:.0f} MB"
                )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="the full run, not --quick")
    parser.add_argument(
        "--out", default=None, help="output folder (default: a temp dir)"
    )
    parser.add_argument(
        "--baseline",
        metavar="DIR",
        default=None,
        help="another checkout: time both, alternated, in processes of their own",
    )
    parser.add_argument(
        "--stages",
        default=None,
        help="with --baseline: the stages to run (default all)",
    )
    parser.add_argument(
        "--rounds", type=int, default=2, help="with --baseline: rounds (default 2)"
    )
    parser.add_argument(
        "--phantom",
        choices=("auto", "measured", "synthetic"),
        default="auto",
        help="with --baseline: the scans' phantom (default auto)",
    )
    args = parser.parse_args()
    print(versions())
    if args.baseline is None:
        _in_process(args)
        return
    if not is_checkout(args.baseline):
        parser.error(f"--baseline {args.baseline!r} is not a vic_drake checkout")
    if args.rounds < 1:
        parser.error(f"--rounds takes an integer >= 1; got {args.rounds}")
    _interleaved(args)


if __name__ == "__main__":
    main()
