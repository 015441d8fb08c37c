"""Do the scans of this checkout log exactly what another checkout's logged?

A speed change must not change behaviour. This runs the same scans (VS-VF
and VS-CF nominal, CS, CF and VS-VF with the phantom lifted, and VS-VF
nominal with the online tissue estimator, online_compare's "online" run;
the synthetic phantom, seeded noise) with the code of ``--baseline DIR`` (another
checkout, e.g. ``git worktree add DIR <commit>``) and with this checkout,
each in a fresh process, and prints for each scan the largest absolute
difference of every logged column that differs. "worst 0" means
bit-identical logs.

    python benchmarks/compare_scan_logs.py --baseline DIR [--duration 9]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile

import pandas as pd
from common import HERE, is_checkout, run_in_checkout, versions

#: (controller, disturbed, online_compare run or None) of the compared scans.
CASES = (
    ("vs-vf", False, None),
    ("vs-cf", False, None),
    ("cs", True, None),
    ("cf", True, None),
    ("vs-vf", True, None),
    ("vs-vf", False, "online"),
)


def _file(controller: str, disturbed: bool, run) -> str:
    return f"{controller}_{int(disturbed)}{'' if run is None else '_' + run}.parquet"


def _worker(out_dir: str, duration_s: float) -> None:
    """Runs the cases with the vic_drake on sys.path; one parquet each."""
    from vic_drake.experiments import run_scan, synthetic_scenario
    from vic_drake.experiments.online_compare import comparison_scenario

    for controller, disturbed, run in CASES:
        scenario = synthetic_scenario(controller, disturbed=disturbed)
        if run is not None:
            scenario = comparison_scenario(scenario, run)
        df = run_scan(scenario, duration_s=duration_s).df.select_dtypes("number")
        df.to_parquet(os.path.join(out_dir, _file(controller, disturbed, run)))


def _run(tree: str, out_dir: str, duration_s: float) -> None:
    command = [sys.executable, os.path.abspath(__file__), "--worker", out_dir]
    command += ["--duration", str(duration_s)]
    run_in_checkout(tree, command)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="DIR", help="the other checkout")
    parser.add_argument("--duration", type=float, default=9.0, help="simulated s")
    parser.add_argument("--worker", metavar="OUT", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if not args.duration > 0:
        parser.error(f"--duration must be > 0; got {args.duration}")
    if args.worker:
        _worker(args.worker, args.duration)
        return 0
    if not is_checkout(args.baseline):
        parser.error(f"--baseline must be a checkout of vic_drake; got {args.baseline}")
    print(versions())
    worst = 0.0
    with tempfile.TemporaryDirectory() as old, tempfile.TemporaryDirectory() as new:
        _run(args.baseline, old, args.duration)
        _run(HERE, new, args.duration)
        for controller, disturbed, run in CASES:
            name = _file(controller, disturbed, run)
            a = pd.read_parquet(os.path.join(old, name))
            b = pd.read_parquet(os.path.join(new, name))
            if list(a.columns) != list(b.columns) or a.shape != b.shape:
                print(f"{name}: columns or shape differ: {a.shape} vs {b.shape}")
                worst = float("inf")
                continue
            diff = (b - a).abs().max()
            moved = diff[diff > 0].sort_values(ascending=False)
            worst = max(worst, float(diff.max()))
            print(
                f"{controller:6s} {'disturbed' if disturbed else 'nominal  '} "
                f"{'' if run is None else run + ' '}"
                f"{len(a)} rows: "
                + (
                    "identical"
                    if moved.empty
                    else ", ".join(f"{k} {v:.3g}" for k, v in moved.head(6).items())
                )
            )
    print(f"worst {worst:g}")
    return 0 if worst == 0.0 else 1


if __name__ == "__main__":
    sys.exit(main())
