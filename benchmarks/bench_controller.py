"""Per-tick cost of the online controller (reference + stiffness QP + tank), per QP solver.

Prints, with the Drake and Python versions, median and p99 wall time per
tick, in microseconds, against the 2,000 us of a 500 Hz loop, for

- the function path: the pure functions of one tick (phantom lookup,
  references, QP, tank), with the exact solver and through the
  MathematicalProgram with every Drake solver of
  ``vic_drake.control.stiffness_qp.program.PROGRAM_SOLVERS`` (OSQP,
  Clarabel, SCS, Clp, NLopt, SNOPT, IPOPT), each one's largest distance
  to the exact solver's K on the same ticks and its failed ticks;
- the Diagram path: ``MakeVariableImpedanceController`` advanced by a
  Simulator (inputs fixed, 500 Hz events of its three LeafSystems), for the
  solvers a scenario can select (exact, OSQP, Clarabel);

then a summary table per solver (the figure of issue 14: function-path QP
median and p99, Diagram-path tick p99, accuracy). With ``--repeats N`` each
tick's figure is the fastest of N computations of it (the Diagram path: N
passes over the same ticks, each with a fresh Diagram): a slowdown that
another process causes in one pass does not count, a tick that is slow in
every pass does. The raw first pass is printed too.

The process restarts once in the environment ``vic-drake`` runs scans in
(its allocator; ``benchmarks/common.py``, ``run_as_vic_drake``); the header
names the allocator.

Each figure is given in wall time (what a real-time loop sees) and in the
thread's CPU time (``time.thread_time``), which excludes the time the thread
waits while other processes run: on a shared machine the wall-time p99 is
set by preemptions (several ms at a load above the core count), the CPU-time
p99 by the code.

The inputs replay the real log ``test_nardi_matForce_lowR`` (VS-VF) when the
data is present, else a synthetic scan. Goals (issue 14): Diagram-path tick
p99 <= 200 us through the MathematicalProgram. No asserts: this prints
figures.

Usage:
    python benchmarks/bench_controller.py [--ticks N] [--diagram-ticks N]
        [--phantom synthetic|measured] [--repeats N] [--solvers exact,osqp,...]
        [--other-ticks N]
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np
from common import comma_list, run_as_vic_drake, versions

from vic_drake.control.params import (
    ControllerParams,
    ReferenceParams,
    StiffnessQpParams,
)
from vic_drake.control.references import (
    force_references,
    in_contact,
    penetration_rate,
    scalar_sampler,
    surface_velocity_initial_state,
    surface_velocity_step,
)
from vic_drake.control.stiffness_qp import (
    StiffnessQp,
    make_stiffness_qp_problem,
    solve_stiffness_qp_exact,
)
from vic_drake.control.stiffness_qp.program import PROGRAM_SOLVERS
from vic_drake.control.tank import tank_step
from vic_drake.paths import has_data, resolve_data_dir
from vic_drake.tissue.phantom import load_phantom

LOOP_US = 2000.0
#: The solvers a scenario can select (StiffnessQpParams.solver): the Diagram
#: path is measured for these.
SCENARIO_SOLVERS = ("exact", "osqp", "clarabel")


def inputs(n: int, phantom):
    """(p_WP, v_WP, x_d, f_W) rows: the real VS-VF log, else a synthetic scan."""
    if has_data():
        from vic_drake.realdata import read_bag

        df = read_bag(resolve_data_dir() / "experiments" / "test_nardi_matForce_lowR")
        df = df.iloc[: min(n, len(df))]
        p = df[["x_m", "y_m", "z_m"]].to_numpy()
        v = df[["vx_m_per_s", "vy_m_per_s", "vz_m_per_s"]].to_numpy()
        xd = df[["x_d_m", "y_d_m", "z_d_m"]].to_numpy()
        f = df[["sensor_force_x_N", "sensor_force_y_N", "sensor_force_z_N"]].to_numpy()
        return "log test_nardi_matForce_lowR", p, v, xd, f
    t = np.arange(n) * 0.002
    x0, x1, y0, y1 = phantom.bounds
    x = 0.5 * (x0 + x1) - 0.01 * t
    y = np.full(n, 0.5 * (y0 + y1))
    zs = np.asarray(phantom.surface_z(x, y), float)
    p = np.column_stack([x, y, zs - 0.005 - 0.001 * np.sin(2 * np.pi * t)])
    v = np.column_stack(
        [np.full(n, -0.01), np.zeros(n), -0.002 * np.pi * np.cos(2 * np.pi * t)]
    )
    xd = np.column_stack([x - 0.002, y, zs - 0.015])
    f = np.column_stack([np.zeros(n), np.zeros(n), np.full(n, -7.0)])
    return "synthetic scan", p, v, xd, f


def median_p99(samples_s) -> tuple[float, float]:
    """Median and 99th percentile of samples in seconds, in microseconds."""
    us = np.asarray(samples_s) * 1e6
    return float(np.median(us)), float(np.percentile(us, 99))


def stats(samples_s) -> str:
    med, p99 = median_p99(samples_s)
    return f"median {med:8.1f} us  p99 {p99:8.1f} us  ({100 * p99 / LOOP_US:5.1f}% of 2 ms)"


def controller_params(solver: str) -> ControllerParams:
    """VS-VF at R = 1e-5 (the replayed log's settings) with the given QP solver.

    Solvers a scenario cannot select are built as "osqp" here: the function
    path constructs its own :class:`StiffnessQp`.
    """
    qp_solver = solver if solver in SCENARIO_SOLVERS else "osqp"
    return ControllerParams(
        qp=StiffnessQpParams(r_weight=[1e-5] * 3, solver=qp_solver),
        reference=ReferenceParams(controller="vs-vf"),
    )


def bench_functions(
    params: ControllerParams, phantom, rows, solver: str, repeats: int = 1
):
    """One tick of the pure functions, as the LeafSystems chain them.

    With repeats > 1 each tick is computed that many times from the same
    state and the fastest time is kept: this removes the multi-millisecond
    preemptions of a shared machine from the p99 (the raw figure, repeats =
    1, keeps them).

    Returns:
        (tick times, QP times, tick thread-CPU times, largest |K - K_exact|
        in N/m over the ticks, number of failed solves); the exact solver's
        K is computed on the same problem outside the timed section.
    """
    ref, qp, tank = params.reference, params.qp, params.tank
    dt = params.period_s
    sample = scalar_sampler(phantom)
    qp_solver = StiffnessQp(solver, osqp_eps=qp.osqp_eps)
    k_min = tuple(qp.stiffness_min_N_per_m)
    filt = surface_velocity_initial_state(ref.surface_velocity_window)
    energy, k_prev = tank.initial_energy_J, k_min
    zeta = qp.damping_ratio
    times, qp_times, cpu_times = [], [], []
    worst, failed = 0.0, 0
    p_all, v_all, xd_all, f_all = (r.tolist() for r in rows)
    for p, v, xd, f in zip(p_all, v_all, xd_all, f_all):
        best = best_qp = best_cpu = math.inf
        for _ in range(repeats):
            c0 = time.thread_time()
            t0 = time.perf_counter()
            surface_z, _, _, kappa, lam = sample(p[0], p[1])
            new_filt, z_surf_dot = surface_velocity_step(filt, surface_z, dt)
            contact = in_contact(f[2], ref)
            refs = force_references(
                contact=contact, kappa=kappa, lam=lam, eps_dot=penetration_rate(v[2], z_surf_dot),
                beta=phantom.beta, ref=ref, qp=qp,
            )  # fmt: skip
            e = (xd[0] - p[0], xd[1] - p[1], xd[2] - p[2])
            e_dot = (-v[0], -v[1], -v[2])
            d = (2 * zeta * math.sqrt(k_prev[0]), 2 * zeta * math.sqrt(k_prev[1]),
                 2 * zeta * math.sqrt(k_prev[2]))  # fmt: skip
            t1 = time.perf_counter()
            problem = None
            if energy >= tank.min_energy_J:
                problem = make_stiffness_qp_problem(
                    e, e_dot, d, refs.force_ref, refs.force_min, energy, dt, qp, tank
                )
                sol = qp_solver.solve(problem, guess=k_prev)
                k = sol.stiffness
            else:
                k = k_min
            t2 = time.perf_counter()
            new_energy = tank_step(energy, e, e_dot, k, k_min, d, dt, tank).energy_J
            t3 = time.perf_counter()
            c3 = time.thread_time()
            best = min(best, t3 - t0)
            best_qp = min(best_qp, t2 - t1)
            best_cpu = min(best_cpu, c3 - c0)
        if problem is not None:
            failed += not sol.success
            k_exact = solve_stiffness_qp_exact(problem).stiffness
            worst = max(worst, *(abs(a - b) for a, b in zip(k, k_exact)))
        filt, energy, k_prev = new_filt, new_energy, k
        times.append(best)
        qp_times.append(best_qp)
        cpu_times.append(best_cpu)
    return times, qp_times, cpu_times, worst, failed


def bench_diagram(params: ControllerParams, phantom, rows, ticks: int):
    """The Diagram advanced by a Simulator, one period at a time."""
    from pydrake.systems.analysis import Simulator

    from vic_drake.systems.controller import MakeVariableImpedanceController

    diagram = MakeVariableImpedanceController(params, phantom=phantom)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    ports = [diagram.GetInputPort(n) for n in
             ("probe.position", "probe.velocity", "target_position", "ft_sensor.force_W")]  # fmt: skip
    p_all, v_all, xd_all, f_all = rows
    simulator.Initialize()
    times, cpu_times = [], []
    for i in range(min(ticks, len(p_all))):
        for port, values in zip(ports, (p_all[i], v_all[i], xd_all[i], f_all[i])):
            port.FixValue(context, values)
        c0 = time.thread_time()
        t0 = time.perf_counter()
        simulator.AdvanceTo((i + 1) * params.period_s)
        diagram.GetOutputPort("stiffness").Eval(context)
        times.append(time.perf_counter() - t0)
        cpu_times.append(time.thread_time() - c0)
    return times, cpu_times


def main():
    run_as_vic_drake()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=5000)
    parser.add_argument("--diagram-ticks", type=int, default=2000)
    parser.add_argument("--phantom", choices=("synthetic", "measured"), default=None)
    parser.add_argument(
        "--repeats", type=int, default=3,
        help="best of N computations of each tick, function path and Diagram "
        "path (N passes of the same ticks); 1 = raw",
    )  # fmt: skip
    parser.add_argument(
        "--solvers", default=",".join(("exact",) + PROGRAM_SOLVERS),
        help="comma-separated QP solvers (default: exact and every Drake solver)",
    )  # fmt: skip
    parser.add_argument(
        "--other-ticks", type=int, default=500,
        help="function-path ticks for solvers a scenario cannot select (IPOPT: ~5 ms each)",
    )  # fmt: skip
    args = parser.parse_args()
    solvers = comma_list(parser, "--solvers", args.solvers)
    for name in solvers:
        if name != "exact" and name not in PROGRAM_SOLVERS:
            parser.error(
                f"--solvers: unknown solver {name!r}; "
                f"choose from {', '.join(('exact',) + PROGRAM_SOLVERS)}"
            )
    kind = args.phantom or ("measured" if has_data() else "synthetic")
    phantom = load_phantom(kind)
    source, *rows = inputs(args.ticks, phantom)
    print(versions())
    print(
        f"inputs: {source}, {len(rows[0])} ticks; phantom: {kind}; loop budget {LOOP_US:.0f} us"
    )
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"machine: {os.cpu_count()} CPUs, 1-min load average {load:.2f} (contention inflates p99)"
    )
    summary = {}
    print("-- function path: one tick = phantom lookup + references + QP + tank")
    for solver in solvers:
        params = controller_params(solver)
        n = len(rows[0]) if solver in SCENARIO_SOLVERS else args.other_ticks
        solver_rows = [r[:n] for r in rows]
        for repeats in sorted({1, args.repeats}):
            total, qp_only, cpu, worst, failed = bench_functions(
                params, phantom, solver_rows, solver, repeats
            )
            tag = "raw" if repeats == 1 else f"best of {repeats}"
            print(f"{solver:9s} tick  {stats(total)}  [wall, {tag}, {n} ticks]")
            print(f"{solver:9s} tick  {stats(cpu)}  [thread CPU, {tag}]")
            print(f"{solver:9s} QP    {stats(qp_only)}  [wall, {tag}]")
            if repeats == args.repeats:  # The summary's figures: best of N.
                summary[solver] = [*median_p99(total), *median_p99(qp_only)]
                summary[solver] += [math.nan, math.nan, math.nan, worst, failed, n]
        print(
            f"{solver:9s} max |K - K_exact| {worst:.1e} N/m, "
            f"{failed} failed solve(s) in {n} ticks"
        )
    print("-- Diagram path (3 LeafSystems, Simulator.AdvanceTo one period per tick)")
    for solver in solvers:
        if solver not in SCENARIO_SOLVERS:
            continue
        passes = [
            bench_diagram(controller_params(solver), phantom, rows, args.diagram_ticks)
            for _ in range(args.repeats)
        ]
        wall, cpu = passes[0]
        print(f"{solver:9s} tick  {stats(wall)}  [wall, raw]")
        print(f"{solver:9s} tick  {stats(cpu)}  [thread CPU, raw]")
        if args.repeats > 1:
            # The same ticks in each pass (fresh Diagram, same inputs): the
            # fastest of the passes per tick, as for the function path.
            wall = np.min([p[0] for p in passes], axis=0)
            cpu = np.min([p[1] for p in passes], axis=0)
            print(f"{solver:9s} tick  {stats(wall)}  [wall, best of {args.repeats}]")
            print(
                f"{solver:9s} tick  {stats(cpu)}  [thread CPU, best of {args.repeats}]"
            )
        summary[solver][4:7] = [*median_p99(wall), median_p99(cpu)[1]]
    tag = "raw" if args.repeats == 1 else f"best of {args.repeats}"
    print(f"-- summary per solver, us ({versions()})")
    print(
        f"{'':9s} {'function path (wall, ' + tag + ')':^38s}  "
        f"{'Diagram path (' + tag + ')':^27s}"
    )
    print(
        f"{'solver':9s} {'tick med':>9s} {'tick p99':>9s} {'QP med':>9s} {'QP p99':>9s}  "
        f"{'med wall':>8s} {'p99 wall':>8s} {'p99 CPU':>8s}  {'max|K-K_exact|':>14s} "
        f"{'failed':>9s}"
    )
    for solver, figures in summary.items():
        t_med, t_p99, q_med, q_p99, d_med, d_p99, d_cpu, worst, failed, n = figures
        diagram = "  ".join(
            f"{v:8.1f}" if not math.isnan(v) else f"{'n/a':>8s}"
            for v in (d_med, d_p99, d_cpu)
        )
        print(
            f"{solver:9s} {t_med:9.1f} {t_p99:9.1f} {q_med:9.1f} {q_p99:9.1f}  "
            f"{diagram}  {worst:10.1e} N/m {failed:4d}/{n:<4d}"
        )
    print("(Diagram path n/a: a scenario cannot select that solver.)")


if __name__ == "__main__":
    main()
