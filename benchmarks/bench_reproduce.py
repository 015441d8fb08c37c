"""Wall time of ``vic-drake reproduce`` per stage (quick mode by default).

Goals (issue): --quick under 5 minutes on a 2-core machine, the full run
under 30 minutes. Prints the stage times and the total; no asserts.

Usage:
    python benchmarks/bench_reproduce.py [--full] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

from common import versions

from vic_drake.analysis.claims import claim_status
from vic_drake.reproduce import ReproduceOptions, reproduce


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="the full run, not --quick")
    parser.add_argument(
        "--out", default=None, help="output folder (default: a temp dir)"
    )
    args = parser.parse_args()
    print(versions())
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


if __name__ == "__main__":
    main()
