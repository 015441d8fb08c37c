"""Instructions per tick of the controller Diagram, counted by callgrind.

The Diagram path of ``bench_controller.py`` (``MakeVariableImpedanceController``
advanced one period per tick by a Simulator, the four inputs fixed from the
replayed log each tick, then the "stiffness" output evaluated), run under
``valgrind --tool=callgrind``: after ``--warmup`` ticks it counts ``--ticks``
ticks, then the same number of the four ``FixValue`` calls alone, and
prints per solver the instructions of a tick without the ``FixValue`` calls
(the timed part of ``bench_controller.py``), beside the same count of
``--baseline DIR`` (another checkout) when given. Wall time swings on a
shared host; these counts repeat to 0.1 %. Needs valgrind.

    python benchmarks/bench_controller_instructions.py [--baseline DIR]
        [--solvers exact,osqp] [--warmup 300] [--ticks 600]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

from common import (
    HERE,
    callgrind_in_checkout,
    check_callgrind_baseline,
    comma_list,
    versions,
)


def _worker(solver: str, warmup: int, ticks: int) -> None:
    """The Diagram loop, with two callgrind dumps: ticks, then FixValue alone."""
    from bench_controller import controller_params, inputs
    from pydrake.systems.analysis import Simulator

    from vic_drake.systems.controller import MakeVariableImpedanceController
    from vic_drake.tissue.phantom import load_phantom

    phantom = load_phantom("measured")
    _, *rows = inputs(warmup + ticks, phantom)
    if len(rows[0]) < warmup + ticks:
        sys.exit(f"the inputs have {len(rows[0])} ticks, fewer than {warmup + ticks}")
    params = controller_params(solver)
    diagram = MakeVariableImpedanceController(params, phantom=phantom)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    names = ("probe.position", "probe.velocity", "target_position", "ft_sensor.force_W")
    ports = [diagram.GetInputPort(name) for name in names]
    stiffness = diagram.GetOutputPort("stiffness")
    simulator.Initialize()
    pid = str(os.getpid())

    def fix(i):
        for port, values in zip(
            ports, (rows[0][i], rows[1][i], rows[2][i], rows[3][i])
        ):
            port.FixValue(context, values)

    def tick(i):
        fix(i)
        simulator.AdvanceTo((i + 1) * params.period_s)
        stiffness.Eval(context)

    for i in range(warmup):
        tick(i)
    subprocess.run(["callgrind_control", "-i", "on", pid], capture_output=True)
    subprocess.run(["callgrind_control", "-z", pid], capture_output=True)
    for i in range(warmup, warmup + ticks):
        tick(i)
    subprocess.run(["callgrind_control", "-d", "ticks", pid], capture_output=True)
    for i in range(warmup, warmup + ticks):
        fix(i)
    subprocess.run(["callgrind_control", "-d", "fixvalue", pid], capture_output=True)
    subprocess.run(["callgrind_control", "-i", "off", pid], capture_output=True)
    print(f"ticks {ticks}")


def _count(tree: str, solver: str, args) -> float:
    """Instructions per Diagram tick (FixValue excluded) of ``tree``."""
    worker = [solver, "--warmup", str(args.warmup), "--ticks", str(args.ticks)]
    ticks, dumps = callgrind_in_checkout(tree, __file__, worker)
    if set(dumps) != {"ticks", "fixvalue"}:
        sys.exit(f"the run of {tree} dumped {sorted(dumps)}, not ticks and fixvalue")
    return (dumps["ticks"] - dumps["fixvalue"]) / ticks


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="DIR", default=None)
    parser.add_argument("--solvers", default="exact,osqp")
    parser.add_argument("--warmup", type=int, default=300)
    parser.add_argument("--ticks", type=int, default=600)
    parser.add_argument("--worker", metavar="SOLVER", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.warmup < 0 or args.ticks < 1:
        parser.error(
            f"need --warmup >= 0, --ticks >= 1; got {args.warmup}, {args.ticks}"
        )
    if args.worker:
        _worker(args.worker, args.warmup, args.ticks)
        return 0
    solvers = comma_list(parser, "--solvers", args.solvers)
    for name in solvers:
        if name not in ("exact", "osqp", "clarabel"):
            parser.error(f"--solvers: {name!r} is not exact, osqp or clarabel")
    check_callgrind_baseline(parser, args.baseline)
    print(versions())
    print(
        f"controller Diagram (VS-VF, log inputs), {args.ticks} ticks after "
        f"{args.warmup}, FixValue excluded"
    )
    trees = {"current": HERE}
    if args.baseline is not None:
        trees = {"baseline": args.baseline, **trees}
    for solver in solvers:
        counts = {name: _count(tree, solver, args) for name, tree in trees.items()}
        for name, tree in trees.items():
            print(
                f"  {solver:<8} {name:<9} {counts[name] / 1e3:7.1f} k instructions "
                f"per tick  ({tree})"
            )
        if args.baseline is not None:
            ratio = counts["current"] / counts["baseline"]
            print(f"  {solver:<8} current / baseline: {ratio:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
