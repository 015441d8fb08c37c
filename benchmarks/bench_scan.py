"""Real-time factor of the full closed-loop VS-VF scan, and where the time goes.

Simulates the VS-VF nominal scan on the synthetic phantom (station with the
UR3e and the Hunt-Crossley tissue force, F/T sensor, FDCC, stiffness QP,
energy tank, logging at 500 Hz) and prints the real-time factor (simulated
seconds per wall-clock second; the goal is >= 2, i.e. twice faster than real
time), beside the ceiling: the same rig (UR3e, tool, lifted phantom, joint
and lift servos, gravity feed-forward: every C++ system of the station, no
Python system) holding its start pose, stepped at the same plant step. Every
figure is printed with its Drake and Python versions and as a fraction of
that ceiling. Then a cProfile breakdown: the slowest functions by own time
and the share of the time spent in each vic_drake system.

    python benchmarks/bench_scan.py [--duration 5] [--scenario diagrams/X.yaml] [--top 25]
        [--qp-solver exact|osqp|clarabel] [--time-step-ms 2] [--repeat 3] [--no-profile]

Figures measured with it, and the changes they led to: docs/decisions.md,
"Scan speed".
"""

from __future__ import annotations

import argparse
import copy
import cProfile
import importlib.metadata
import io
import platform
import pstats
import statistics
import time
from collections import defaultdict
from dataclasses import replace

import numpy as np


def versions() -> str:
    """Drake and Python versions, printed with every figure."""
    return (
        f"drake {importlib.metadata.version('drake')}, "
        f"python {platform.python_version()}, numpy {np.__version__}"
    )


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
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1; got {args.repeat}")

    from vic_drake.experiments import run_scan, synthetic_scenario
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
    print(versions())
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
    print(f"per 2 ms tick       {1e3 * result.wall_s / (result.sim_s / 0.002):.3f} ms")
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
