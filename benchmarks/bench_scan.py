"""Real-time factor of the full closed-loop VS-VF scan, and where the time goes.

Simulates the VS-VF nominal scan on the synthetic phantom (station with the
UR3e and the Hunt-Crossley tissue force, F/T sensor, FDCC, stiffness QP,
energy tank, logging at 500 Hz) and prints the real-time factor (simulated
seconds per wall-clock second; the goal is >= 4), beside the ceiling: the same rig (UR3e, tool, lifted phantom, joint
and lift servos, gravity feed-forward: every C++ system of the station, no
Python system) holding its start pose, stepped at the same plant step. Every
figure is printed with its Drake and Python versions and as a fraction of
that ceiling. Then a cProfile breakdown: the slowest functions by own time
and the share of the time spent in each vic_drake system.

    python benchmarks/bench_scan.py [--duration 5] [--scenario diagrams/X.yaml] [--top 25]
        [--qp-solver exact|osqp|clarabel] [--time-step-ms 2] [--repeat 3] [--no-profile]
        [--baseline DIR]

With ``--baseline DIR`` (another checkout, e.g. ``git worktree add DIR
<commit>``), the scan of that code and of this checkout alternate, each in a
fresh process, ``--repeat`` times, and the medians are printed side by side:
the before/after figure of a change on a shared, noisy host.

Figures measured with it, and the changes they led to: docs/decisions.md,
"Scan speed".
"""

from __future__ import annotations

import argparse
import copy
import cProfile
import io
import json
import os
import pstats
import statistics
import sys
import time
from collections import defaultdict
from dataclasses import replace

from common import HERE, is_checkout, run_as_vic_drake, run_in_checkout, versions


def plant_ceiling_rtf(scenario, duration_s: float) -> tuple[float, float]:
    """Real-time factor of the station's C++ core alone (no Python system).

    The rig of :func:`vic_drake.station.AddRig` (plant with the UR3e, tool and
    lifted phantom, joint and lift servos, gravity feed-forward) holds the
    scan's start pose, stepped at the scenario's plant step: what a scan
    would cost if every Python system were free.
    """
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from vic_drake.experiments import initial_joint_positions, load_scenario_phantom
    from vic_drake.station import AddRig

    q0 = initial_joint_positions(scenario)
    builder = DiagramBuilder()
    rig = AddRig(
        builder, scenario.station, load_scenario_phantom(scenario), initial_q=q0
    )
    hold = builder.AddSystem(ConstantVectorSource(q0))
    lift = builder.AddSystem(ConstantVectorSource([0.0]))
    builder.Connect(hold.get_output_port(), rig.position_command)
    builder.Connect(lift.get_output_port(), rig.phantom_lift)
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    t0, c0 = time.perf_counter(), time.process_time()
    simulator.AdvanceTo(duration_s)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return duration_s / wall, duration_s / cpu


def _scenario(args):
    """The benchmarked scenario, with the command line's overrides."""
    from vic_drake.experiments import synthetic_scenario
    from vic_drake.scenario import load_scenario

    scenario = (
        load_scenario(args.scenario) if args.scenario else synthetic_scenario("vs-vf")
    )
    if args.qp_solver is not None:
        c = scenario.controller
        qp = replace(c.qp, solver=args.qp_solver)
        scenario = replace(scenario, controller=replace(c, qp=qp))
    if args.time_step_ms is not None:
        station = copy.deepcopy(scenario.station)
        station.plant.time_step = 1e-3 * args.time_step_ms
        scenario = replace(scenario, station=station.validate())
    return scenario


def _worker(args) -> None:
    """One scan in this process; prints its figures as one JSON line."""
    from vic_drake.experiments import run_scan

    scenario = _scenario(args)
    result = run_scan(scenario, duration_s=args.duration)
    ticks = result.sim_s / scenario.station.plant.time_step
    print(
        json.dumps(
            {
                "rtf": result.rtf,
                "cpu_rtf": result.sim_s / result.cpu_s,
                "ms_per_tick": 1e3 * result.wall_s / ticks,
                "versions": versions(),
            }
        )
    )


def _run_tree(tree: str, args) -> dict:
    """One scan of the code in ``tree`` (a checkout), in a fresh process."""
    command = [sys.executable, os.path.abspath(__file__), "--worker"]
    command += ["--duration", str(args.duration)]
    for option in ("scenario", "qp_solver", "time_step_ms"):
        value = getattr(args, option)
        if value is not None:
            command += [f"--{option.replace('_', '-')}", str(value)]
    done = run_in_checkout(tree, command)
    return json.loads(done.stdout.strip().splitlines()[-1])


def _compare(args) -> None:
    """The scan of this checkout and of ``--baseline``, alternated, in fresh processes."""
    trees = {"baseline": args.baseline, "current": HERE}
    runs = {name: [] for name in trees}
    for _ in range(args.repeat):  # Alternated: the host is shared and noisy.
        for name, tree in trees.items():
            runs[name].append(_run_tree(tree, args))
    print(f"{args.repeat} run(s) of each, alternated; medians:")
    for name, tree in trees.items():
        rtf = statistics.median(r["rtf"] for r in runs[name])
        cpu = statistics.median(r["cpu_rtf"] for r in runs[name])
        tick = statistics.median(r["ms_per_tick"] for r in runs[name])
        print(
            f"  {name:<9} RTF {rtf:6.3f} wall, {cpu:6.3f} CPU, {tick:6.3f} ms per tick"
            f"  ({runs[name][0]['versions']}; {tree})"
        )
    ratio = statistics.median(
        c["rtf"] / b["rtf"]
        for c, b in zip(runs["current"], runs["baseline"], strict=True)
    )
    print(f"  current / baseline RTF, median of the pairs: {ratio:.2f}x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=5.0, help="simulated time, s")
    parser.add_argument(
        "--scenario", default=None, help="scenario YAML (default: VS-VF nominal)"
    )
    parser.add_argument("--top", type=int, default=25, help="rows of the profile")
    parser.add_argument("--no-profile", action="store_true", help="timing only")
    parser.add_argument(
        "--qp-solver",
        choices=("exact", "osqp", "clarabel"),
        default=None,
        help="stiffness QP solver (default: the scenario's)",
    )
    parser.add_argument(
        "--time-step-ms",
        type=float,
        default=None,
        help="MultibodyPlant step, ms (default: the scenario's)",
    )
    parser.add_argument(
        "--repeat",
        type=int,
        default=1,
        help="runs of the scan and of the ceiling, alternated; medians are printed",
    )
    parser.add_argument(
        "--baseline",
        metavar="DIR",
        default=None,
        help="another checkout of vic_drake (e.g. a git worktree of an older "
        "commit): its scan and this one's alternate, each in a fresh process",
    )
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1; got {args.repeat}")
    if not args.duration > 0:
        parser.error(f"--duration must be > 0; got {args.duration}")
    if args.baseline is not None and not is_checkout(args.baseline):
        parser.error(f"--baseline must be a checkout of vic_drake; got {args.baseline}")
    if args.worker:
        _worker(args)
        return
    if args.baseline is None:
        # In this process: the allocator vic-drake runs scans with. (With
        # --baseline each checkout's workers get their own.)
        run_as_vic_drake()
    print(versions())
    if args.baseline is not None:
        _compare(args)
        return

    from vic_drake.experiments import run_scan

    scenario = _scenario(args)
    scans, ceilings = [], []
    for _ in range(args.repeat):  # Alternated: the host is shared and noisy.
        t0 = time.perf_counter()
        result = run_scan(scenario, duration_s=args.duration)
        scans.append((result, time.perf_counter() - t0))
        ceilings.append(plant_ceiling_rtf(scenario, args.duration))
    result, total = sorted(scans, key=lambda r: r[0].rtf)[len(scans) // 2]
    ceiling = statistics.median(c[0] for c in ceilings)
    ceiling_cpu = statistics.median(c[1] for c in ceilings)
    print(f"scenario            {scenario.name}")
    print(
        f"plant step          {1e3 * scenario.station.plant.time_step:g} ms, "
        f"QP solver {scenario.controller.qp.solver}"
    )
    print(f"simulated           {result.sim_s:.2f} s (median of {args.repeat} run(s))")
    print(f"build + IK          {result.build_s:.2f} s")
    print(f"simulation (wall)   {result.wall_s:.2f} s")
    print(f"total (wall)        {total:.2f} s")
    print(f"simulation (CPU)    {result.cpu_s:.2f} s")
    print(f"real-time factor    {result.rtf:.3f}  (wall clock; goal >= 4)")
    print(
        f"RTF on CPU time     {result.sim_s / result.cpu_s:.3f}  (with a core to itself)"
    )
    ticks = result.sim_s / scenario.station.plant.time_step
    print(f"per tick            {1e3 * result.wall_s / ticks:.3f} ms")
    print(
        f"plant-only ceiling  RTF {ceiling:.3f} wall, {ceiling_cpu:.3f} CPU (the rig "
        "without Python systems)"
    )
    print(
        f"fraction of ceiling {result.rtf / ceiling:.1%} wall, "
        f"{result.sim_s / result.cpu_s / ceiling_cpu:.1%} CPU"
    )
    if args.no_profile:
        return

    profiler = cProfile.Profile()
    profiler.enable()
    run_scan(scenario, duration_s=args.duration)
    profiler.disable()
    stream = io.StringIO()
    stats = pstats.Stats(profiler, stream=stream)
    stats.sort_stats("tottime").print_stats(args.top)
    print(stream.getvalue())

    # Own time per source file: which module (system) costs what.
    per_file = defaultdict(float)
    total_tt = 0.0
    for (filename, _, func), (_, _, tt, _, _) in stats.stats.items():
        total_tt += tt
        if "vic_drake" in filename:
            key = filename[filename.index("vic_drake") :]
        elif filename == "~":
            key = f"built-in: {func}"
        else:
            key = "other python (numpy, pydrake wrappers, ...)"
        per_file[key] += tt
    print("own time by module (profiled run, profiler overhead included):")
    for key, tt in sorted(per_file.items(), key=lambda kv: -kv[1])[:20]:
        print(f"  {100 * tt / total_tt:5.1f} %  {tt:7.2f} s  {key}")


if __name__ == "__main__":
    main()
