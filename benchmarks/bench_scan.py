"""Real-time factor of the full closed-loop VS-VF scan, and where the time goes.

Simulates the VS-VF nominal scan on the synthetic phantom (station with the
UR3e and the Hunt-Crossley tissue force, F/T sensor, FDCC, stiffness QP,
energy tank, logging at 500 Hz) and prints the real-time factor (simulated
seconds per wall-clock second; the goal is >= 2, i.e. twice faster than real
time), then a cProfile breakdown: the slowest functions by own time and the
share of the time spent in each vic_drake system.

    python benchmarks/bench_scan.py [--duration 5] [--scenario diagrams/X.yaml] [--top 25]
        [--qp-solver exact|osqp|clarabel] [--time-step-ms 2] [--no-profile]

Figures measured with it, and the changes they led to: docs/decisions.md,
"Scan speed".
"""

from __future__ import annotations

import argparse
import copy
import cProfile
import io
import pstats
import time
from collections import defaultdict
from dataclasses import replace


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
    args = parser.parse_args()

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
    t0 = time.perf_counter()
    result = run_scan(scenario, duration_s=args.duration)
    total = time.perf_counter() - t0
    print(f"scenario            {scenario.name}")
    print(
        f"plant step          {1e3 * scenario.station.plant.time_step:g} ms, "
        f"QP solver {scenario.controller.qp.solver}"
    )
    print(f"simulated           {result.sim_s:.2f} s")
    print(f"build + IK          {result.build_s:.2f} s")
    print(f"simulation (wall)   {result.wall_s:.2f} s")
    print(f"total (wall)        {total:.2f} s")
    print(f"simulation (CPU)    {result.cpu_s:.2f} s")
    print(f"real-time factor    {result.rtf:.3f}  (wall clock; goal >= 2)")
    print(
        f"RTF on CPU time     {result.sim_s / result.cpu_s:.3f}  (with a core to itself)"
    )
    print(f"per 2 ms tick       {1e3 * result.wall_s / (result.sim_s / 0.002):.3f} ms")
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
