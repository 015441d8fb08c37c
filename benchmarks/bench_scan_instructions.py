"""Instructions per tick of the closed-loop scan, counted by callgrind.

Wall and CPU times swing by 2x on a shared host; instruction counts repeat
to 0.1 %. This runs the VS-VF nominal scan on the synthetic phantom under
``valgrind --tool=callgrind`` with instrumentation off until the tip is in
the tissue (``--from``), counts the instructions of the ticks up to
``--to`` and prints them per tick, beside the same count of ``--baseline
DIR`` (another checkout) when given. Needs valgrind (Debian's package);
each run takes a few minutes.

    python benchmarks/bench_scan_instructions.py [--baseline DIR] [--from 3.2] [--to 3.4]
        [--controller vs-vf] [--online]

``--online``: the scan with the online tissue estimator (online_compare's
"online" run of that controller's scenario).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

from common import HERE, callgrind_in_checkout, check_callgrind_baseline, versions


def _worker(controller: str, t0: float, t1: float, online: bool) -> None:
    """The scan, with callgrind's instrumentation on from t0 to t1 only."""
    from pydrake.common import RandomGenerator
    from pydrake.systems.analysis import Simulator

    from vic_drake.experiments import synthetic_scenario
    from vic_drake.experiments.scan_diagram import (
        MakeScanDiagram,
        initial_joint_positions,
        set_initial_state,
    )

    scenario = synthetic_scenario(controller)
    if online:
        from vic_drake.experiments.online_compare import comparison_scenario

        scenario = comparison_scenario(scenario, "online")
    diagram, _ = MakeScanDiagram(scenario)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    diagram.SetRandomContext(context, RandomGenerator(scenario.seed))
    set_initial_state(diagram, context, initial_joint_positions(scenario))
    simulator.Initialize()
    simulator.AdvanceTo(t0)
    pid = str(os.getpid())
    subprocess.run(["callgrind_control", "-i", "on", pid], capture_output=True)
    simulator.AdvanceTo(t1)
    subprocess.run(["callgrind_control", "-d", "window", pid], capture_output=True)
    subprocess.run(["callgrind_control", "-i", "off", pid], capture_output=True)
    print(f"ticks {round((t1 - t0) / scenario.station.plant.time_step)}")


def _count(tree: str, args) -> float:
    """Instructions per tick of the scan of ``tree``."""
    worker = [args.controller, "--from", str(args.t0), "--to", str(args.t1)]
    worker += ["--online"] if args.online else []
    ticks, dumps = callgrind_in_checkout(tree, __file__, worker)
    if "window" not in dumps:
        sys.exit(f"the run of {tree} dumped {sorted(dumps)}, not the scan window")
    return dumps["window"] / ticks


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="DIR", default=None)
    parser.add_argument("--controller", default="vs-vf")
    parser.add_argument("--from", dest="t0", type=float, default=3.2)
    parser.add_argument("--to", dest="t1", type=float, default=3.4)
    parser.add_argument(
        "--online", action="store_true", help="with the online tissue estimator"
    )
    parser.add_argument("--worker", metavar="CONTROLLER", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if not 0 <= args.t0 < args.t1:
        parser.error(f"need 0 <= --from < --to; got {args.t0}, {args.t1}")
    if args.worker:
        _worker(args.worker, args.t0, args.t1, args.online)
        return 0
    check_callgrind_baseline(parser, args.baseline)
    print(versions())
    online = " (online estimator)" if args.online else ""
    print(
        f"{args.controller}{online} scan, ticks from {args.t0} s to {args.t1} s (in contact)"
    )
    trees = {"current": HERE}
    if args.baseline is not None:
        trees = {"baseline": args.baseline, **trees}
    counts = {name: _count(tree, args) for name, tree in trees.items()}
    for name, tree in trees.items():
        print(
            f"  {name:<9} {counts[name] / 1e6:6.3f} M instructions per tick  ({tree})"
        )
    if args.baseline is not None:
        print(f"  current / baseline: {counts['current'] / counts['baseline']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
