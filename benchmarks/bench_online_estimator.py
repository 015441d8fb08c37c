"""Cost of one online-estimator tick as a function (RLS, EKF variants).

Prints the median and p99 wall time of ``rls_step`` / ``ekf_step`` (and
``ekf_slope_step``) over a simulated 1.5 Hz Hunt-Crossley palpation (20 s
at 500 Hz) and over the shared palpation log if the data folder is
present. The issue's budget is 30 us p99 per tick. Run:

    python benchmarks/bench_online_estimator.py [--baseline DIR] [--repeats 7]

Without ``--baseline``: the best of three runs per figure. With
``--baseline DIR`` (another checkout): this checkout's functions and
DIR's, each in its own process, time the same runs in turn (the order
alternating from one repeat to the next, so that the host's load falls on
both), and the figures are the medians over ``--repeats`` runs.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

import numpy as np
from common import HERE, checkout_environment, is_checkout, versions

from vic_drake.estimation.online import OnlineEstimatorParams, run_online
from vic_drake.paths import has_data, resolve_data_dir

VARIANTS = {
    "rls": OnlineEstimatorParams(method="rls"),
    "ekf (kappa, lam)": OnlineEstimatorParams(method="ekf"),
    "ekf (+ surface)": OnlineEstimatorParams(
        method="ekf", surface_walk_m_per_sqrt_s=1e-3
    ),
    "ekf (+ surface, beta)": OnlineEstimatorParams(
        method="ekf", surface_walk_m_per_sqrt_s=1e-3, estimate_beta=True
    ),
    # The slope fit runs every tick (its surface is not used: the log's is
    # given; benchmarks/bench_slope_fit.py runs it on an unknown surface).
    "ekf (+ slope fit)": OnlineEstimatorParams(method="ekf", surface_from_slope=True),
}


def simulated(duration_s=20.0):
    rng = np.random.default_rng(0)
    t = np.arange(0.0, duration_s, 0.002)
    eps = 0.006 - 0.003 * np.cos(2 * np.pi * 1.5 * t)
    eps_dot = 0.003 * 2 * np.pi * 1.5 * np.sin(2 * np.pi * 1.5 * t)
    force = (4000 + 30000 * eps_dot) * eps**1.35 + rng.normal(0, 0.05, t.size)
    return t, 0.1 - eps, -eps_dot, force, 0.1


def logs() -> dict:
    """The logs timed: name -> the arguments of ``run_online`` before params."""
    out = {"simulated 1.5 Hz": simulated()}
    if has_data():
        from vic_drake.estimation.palpation import PalpationData
        from vic_drake.realdata import read_bag

        df = read_bag(resolve_data_dir() / "palpation" / "test_soft_2hz")
        d = PalpationData.from_frame(df)
        out["palpation/test_soft_2hz"] = (
            d.t_s,
            d.z_m,
            df["vz_m_per_s"].to_numpy()[: d.n],
            d.force_N,
            d.surface_z_m,
        )
    return out


def timed(args, params) -> tuple[float, float]:
    """(median, p99) of one run's ticks, us."""
    ticks = run_online(*args, params).tick_s * 1e6
    return float(np.median(ticks)), float(np.percentile(ticks, 99))


def _worker() -> None:
    """Times the runs named on stdin ("log<TAB>variant"), one JSON line each."""
    import vic_drake

    data = logs()
    print(json.dumps(os.path.dirname(os.path.dirname(vic_drake.__file__))), flush=True)
    for line in sys.stdin:
        log, name = line.rstrip("\n").split("\t")
        print(json.dumps(timed(data[log], VARIANTS[name])), flush=True)


def _start(tree: str) -> subprocess.Popen:
    command = [sys.executable, os.path.abspath(__file__), "--worker"]
    worker = subprocess.Popen(
        command,
        env=checkout_environment(tree),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    loaded = json.loads(worker.stdout.readline())
    if os.path.realpath(loaded) != os.path.realpath(tree):
        sys.exit(f"the worker for {tree} imported vic_drake from {loaded}")
    return worker


def _ask(worker: subprocess.Popen, log: str, name: str) -> tuple[float, float]:
    worker.stdin.write(f"{log}\t{name}\n")
    worker.stdin.flush()
    return tuple(json.loads(worker.stdout.readline()))


def compare(baseline: str, repeats: int) -> None:
    """Both checkouts' figures, runs alternated, medians over ``repeats``."""
    trees = {"baseline": baseline, "current": HERE}
    workers = {name: _start(tree) for name, tree in trees.items()}
    names = list(trees)
    log_names = list(logs())
    runs = {(log, v, c): [] for log in log_names for v in VARIANTS for c in names}
    for r in range(repeats):
        for log in log_names:
            for v in VARIANTS:
                for c in names if r % 2 == 0 else names[::-1]:
                    runs[log, v, c].append(_ask(workers[c], log, v))
    for worker in workers.values():
        worker.stdin.close()
        worker.wait()
    print(f"medians of {repeats} runs; baseline {baseline}")
    for log in log_names:
        for v in VARIANTS:
            figures = []
            for c in names:
                med, p99 = np.median(np.array(runs[log, v, c]), axis=0)
                figures.append(f"{c} median {med:5.1f} p99 {p99:5.1f}")
            print(f"{log:<24} {v:<22} " + "   ".join(figures) + " us")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="DIR", default=None)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        _worker()
        return 0
    if args.repeats < 1:
        parser.error(f"--repeats must be >= 1; got {args.repeats}")
    if args.baseline is not None and not is_checkout(args.baseline):
        parser.error(f"--baseline must be a checkout of vic_drake; got {args.baseline}")
    print(versions())
    if args.baseline is not None:
        compare(args.baseline, args.repeats)
        return 0
    for log, run_args in logs().items():
        for name, params in VARIANTS.items():
            # Best of three runs per percentile (machine load).
            figures = np.array([timed(run_args, params) for _ in range(3)])
            med, p99 = figures.min(axis=0)
            print(f"{log:<26} {name:<24} median {med:5.1f} us   p99 {p99:5.1f} us")
    return 0


if __name__ == "__main__":
    sys.exit(main())
