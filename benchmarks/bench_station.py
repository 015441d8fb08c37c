"""Real-time factor of the station, alone and with FDCC holding contact.

Prints, for each case, simulated seconds per wall second (RTF > 1 is faster
than real time), and for the contact case the top cProfile entries (where
the wall time goes: the C++ plant step shows as ``AdvanceTo``'s own time,
each Python LeafSystem under its method names). No asserts: figures only.

Cases:
- ``free``: station only, arm holding a pose 2 cm above the tissue.
- ``press``: station only, arm holding a pose 1 cm into the tissue.
- ``fdcc_cf``: station + FdccController, K_z = 0 and a 7 N force target
  (the CF use), starting 5 mm above the surface.
- ``fdcc_cs``: station + FdccController, K = 400 N/m, target 1.5 cm below
  the surface (the CS use).

Usage:
    python benchmarks/bench_station.py [--duration S] [--phantom synthetic|measured]
        [--no-robot-contact] [--profile-top N]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import time

import numpy as np
from common import versions
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, Demultiplexer

from vic_drake.control.fdcc import FdccParams
from vic_drake.station import MakeStation, StationParams, initial_q_for_tip
from vic_drake.systems.fdcc import AddFdccInputs, FdccController
from vic_drake.tissue import load_phantom

XY = (-0.06, -0.36)


def _station_only(params, phantom, depth_m):
    s = float(phantom.surface_z(*XY))
    q = initial_q_for_tip([*XY, s - depth_m], params)
    station = MakeStation(params, phantom=phantom, initial_q=q)
    context = station.CreateDefaultContext()
    station.GetInputPort("ur3e.position_command").FixValue(context, q)
    station.GetInputPort("phantom.lift").FixValue(context, [0.0])
    return Simulator(station, context), station, context


def _with_fdcc(params, phantom, *, stiffness, target_dz, target_force):
    s = float(phantom.surface_z(*XY))
    q = initial_q_for_tip([*XY, s + 0.005], params)
    builder = DiagramBuilder()
    station = builder.AddNamedSystem(
        "station", MakeStation(params, phantom=phantom, initial_q=q)
    )
    fdcc = builder.AddNamedSystem(
        "fdcc", FdccController(FdccParams(), station_params=params, initial_q=q)
    )
    demux = builder.AddSystem(Demultiplexer([6, 6]))
    builder.Connect(station.GetOutputPort("ur3e.state"), demux.get_input_port())
    inputs = AddFdccInputs(builder, fdcc)
    builder.Connect(demux.get_output_port(0), inputs["joint_positions"])
    builder.Connect(
        station.GetOutputPort("ft_sensor.force_W"), inputs["ft_sensor.force_W"]
    )
    builder.Connect(
        fdcc.get_position_command_output_port(),
        station.GetInputPort("ur3e.position_command"),
    )
    for port, value in (
        (inputs["target_position"], [*XY, s + target_dz]),
        (inputs["stiffness"], stiffness),
        (inputs["target_force"], target_force),
        (station.GetInputPort("phantom.lift"), [0.0]),
    ):
        source = builder.AddSystem(ConstantVectorSource(np.asarray(value, float)))
        builder.Connect(source.get_output_port(), port)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    return (
        simulator,
        station,
        station.GetMyContextFromRoot(simulator.get_mutable_context()),
    )


def _time(simulator, duration, profile_top=0):
    simulator.Initialize()
    profiler = cProfile.Profile() if profile_top else None
    t0 = time.perf_counter()
    if profiler:
        profiler.enable()
    simulator.AdvanceTo(simulator.get_context().get_time() + duration)
    if profiler:
        profiler.disable()
    wall = time.perf_counter() - t0
    report = ""
    if profiler:
        out = io.StringIO()
        pstats.Stats(profiler, stream=out).sort_stats("tottime").print_stats(
            profile_top
        )
        report = out.getvalue()
    return wall, report


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--duration", type=float, default=3.0, help="simulated seconds per case"
    )
    parser.add_argument(
        "--phantom", choices=("synthetic", "measured"), default="synthetic"
    )
    parser.add_argument(
        "--no-robot-contact",
        action="store_true",
        help="filter the links' safety contact with the phantom",
    )
    parser.add_argument(
        "--profile-top",
        type=int,
        default=15,
        help="cProfile entries to print for the fdcc_cf case (0: none)",
    )
    args = parser.parse_args(argv)
    print(versions())
    phantom = load_phantom(args.phantom)
    params = StationParams(robot_contact=not args.no_robot_contact)
    print(
        f"phantom={args.phantom} robot_contact={params.robot_contact} "
        f"time_step={params.plant.time_step} s, {args.duration} s simulated per case"
    )
    cases = {
        "free": lambda: _station_only(params, phantom, -0.02),
        "press": lambda: _station_only(params, phantom, 0.01),
        "fdcc_cf": lambda: _with_fdcc(
            params,
            phantom,
            stiffness=[300, 300, 0],
            target_dz=0.005,
            target_force=[0, 0, -7.0],
        ),
        "fdcc_cs": lambda: _with_fdcc(
            params,
            phantom,
            stiffness=[400] * 3,
            target_dz=-0.015,
            target_force=[0, 0, 0],
        ),
    }
    for name, make in cases.items():
        t0 = time.perf_counter()
        simulator, station, context = make()
        build = time.perf_counter() - t0
        top = args.profile_top if name == "fdcc_cf" else 0
        wall, report = _time(simulator, args.duration, top)
        f = station.GetOutputPort("tissue.force_W").Eval(context)[2]
        fs = station.GetOutputPort("ft_sensor.force_W").Eval(context)[2]
        print(
            f"{name:8s} build {build:5.2f} s  wall {wall:6.2f} s  RTF {args.duration / wall:5.2f}"
            f"  tissue force {f:6.2f} N  sensor z {fs:6.2f} N"
        )
        if report:
            print(report)


if __name__ == "__main__":
    main()
