"""``vic-drake compare-online``'s wall time and peak memory: this checkout
against another.

Runs the same comparison sweep (default: the tracker and the +30 % map at
2.9, 3.0 and 3.1 Hz on the synthetic phantom, F_min,z = -9 N, whole scans:
6 scans) with this checkout and with ``--baseline DIR`` (another checkout,
e.g. ``git worktree add DIR <commit>``), alternating which goes first, and
prints each run's wall time and the largest resident set of any process of
the command (the command itself, a Dask worker or a scan's own process:
``ru_maxrss`` of ``wait4``), and whether the two checkouts' JSON scores
agree. A checkout whose sweep runs in one process grows by each scan's
Diagram (pydrake never frees one with Python systems); one that runs each
scan in a process of its own on Dask workers does not.

    python benchmarks/bench_compare_online.py --baseline DIR [--repeats 2]
        [--workers N] [-- extra compare-online arguments]
"""

from __future__ import annotations

import argparse
import json
import sys

from common import HERE, is_checkout, run_timed, versions

DEFAULT = [
    "nominal_vs_vf_synthetic",
    "online_dither_tracker",
    "wrong_map_+30_dither",
    "--dither-hz", "2.9", "3.0", "3.1",
    "--force-min-z", "-9",
    "--against", "wrong_map_+30_dither",
]  # fmt: skip


def run(tree: str, args: list[str]) -> tuple[float, float, dict]:
    """(wall s, peak RSS MB of any process of the command, its JSON)."""
    command = [sys.executable, "-m", "vic_drake.cli", "compare-online", *args, "--json"]
    out, wall, peak = run_timed(tree, command, cwd=tree)
    return wall, peak, json.loads(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", required=True, metavar="DIR")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="this checkout's --workers (default: its own default)",
    )
    parser.add_argument("extra", nargs="*", help="compare-online arguments")
    args = parser.parse_args()
    if not is_checkout(args.baseline):
        parser.error(f"--baseline must be a checkout of vic_drake; got {args.baseline}")
    sweep = args.extra or DEFAULT
    mine = sweep + ([] if args.workers is None else ["--workers", str(args.workers)])
    print(versions())
    print("compare-online " + " ".join(sweep))
    results = {"baseline": [], "this": []}
    for i in range(args.repeats):
        order = [("baseline", args.baseline, sweep), ("this", HERE, mine)]
        for name, tree, argv in order if i % 2 == 0 else order[::-1]:
            wall, rss, scores = run(tree, argv)
            results[name].append((wall, rss, scores))
            print(f"{name:8s} run {i + 1}: {wall:6.1f} s, peak RSS {rss:6.0f} MB")
    agree = all(
        a[2]["scores"] == b[2]["scores"]
        for a, b in zip(results["baseline"], results["this"], strict=True)
    )
    for name, rows in results.items():
        walls = sorted(r[0] for r in rows)
        print(
            f"{name:8s} best {walls[0]:.1f} s, peak RSS {max(r[1] for r in rows):.0f} MB"
        )
    print(f"scores identical: {agree}")


if __name__ == "__main__":
    main()
