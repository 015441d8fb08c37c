"""Instructions per tick of the online estimators' step functions, by callgrind.

The runs of ``bench_online_estimator.py`` (its variants, over its logs), the
step function called in a plain loop (no timing), under ``valgrind
--tool=callgrind``: instrumentation on for ``--ticks`` ticks after
``--warmup``, one dump per run. Prints the instructions per tick, beside
those of ``--baseline DIR`` (another checkout) when given. Wall time swings
on a shared host; these counts repeat to 0.1 %. Needs valgrind.

    python benchmarks/bench_online_instructions.py [--baseline DIR]
        [--warmup 500] [--ticks 3000]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

import numpy as np
from common import HERE, callgrind_in_checkout, check_callgrind_baseline, versions


def _worker(warmup: int, ticks: int) -> None:
    """Every (log, variant) run, one callgrind dump each, labelled L<i>V<j>."""
    from bench_online_estimator import VARIANTS, logs

    from vic_drake.estimation.online import estimator_functions

    pid = str(os.getpid())
    for i, args in enumerate(logs().values()):
        t = np.asarray(args[0], float)
        columns = [np.broadcast_to(np.asarray(a, float), t.shape) for a in args]
        rows = list(zip(*(c.tolist() for c in columns)))
        if len(rows) < warmup + ticks:
            sys.exit(f"log {i} has {len(rows)} ticks, fewer than {warmup + ticks}")
        for j, params in enumerate(VARIANTS.values()):
            init, step = estimator_functions(params)
            state = init(params)
            for row in rows[:warmup]:
                state, _ = step(state, *row, params)
            window = rows[warmup : warmup + ticks]
            subprocess.run(["callgrind_control", "-i", "on", pid], capture_output=True)
            subprocess.run(["callgrind_control", "-z", pid], capture_output=True)
            for row in window:
                state, _ = step(state, *row, params)
            label = f"L{i}V{j}"
            subprocess.run(["callgrind_control", "-d", label, pid], capture_output=True)
            subprocess.run(["callgrind_control", "-i", "off", pid], capture_output=True)
    print(f"ticks {ticks}")


def _count(tree: str, args) -> dict[str, float]:
    """Instructions per tick of ``tree``, by dump label."""
    worker = ["--warmup", str(args.warmup), "--ticks", str(args.ticks)]
    ticks, dumps = callgrind_in_checkout(tree, __file__, worker)
    return {label: count / ticks for label, count in dumps.items()}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="DIR", default=None)
    parser.add_argument("--warmup", type=int, default=500)
    parser.add_argument("--ticks", type=int, default=3000)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.warmup < 0 or args.ticks < 1:
        parser.error(
            f"need --warmup >= 0, --ticks >= 1; got {args.warmup}, {args.ticks}"
        )
    if args.worker:
        _worker(args.warmup, args.ticks)
        return 0
    check_callgrind_baseline(parser, args.baseline)
    from bench_online_estimator import VARIANTS, logs

    print(versions())
    print(f"{args.ticks} ticks after {args.warmup}, k instructions per tick")
    trees = {"current": HERE}
    if args.baseline is not None:
        trees = {"baseline": args.baseline, **trees}
    counts = {name: _count(tree, args) for name, tree in trees.items()}
    for i, log in enumerate(logs()):
        for j, variant in enumerate(VARIANTS):
            label = f"L{i}V{j}"
            line = f"{log:<24} {variant:<22}"
            for name in trees:
                line += f" {name} {counts[name].get(label, float('nan')) / 1e3:6.1f}"
            if args.baseline is not None:
                ratio = counts["current"][label] / counts["baseline"][label]
                line += f"   current / baseline {ratio:.3f}"
            print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
