"""One tick's stiffness QP as numbers: the problem, its answer, cost and checks.

:func:`make_stiffness_qp_problem` assembles the problem from the
measurement, the references and the tank (its two rows inlined from
:func:`vic_drake.control.tank.tank_qp_rows`); :func:`stiffness_qp_cost` and
:func:`stiffness_qp_violation` evaluate a candidate stiffness;
:func:`fallback_solution` is the defined safe answer (K_min) of a failed
solve, shared by both solvers.
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

from vic_drake.control.params import StiffnessQpParams, TankParams


class StiffnessQpProblem(NamedTuple):
    """The numbers of one tick's QP (all length-3 tuples unless noted).

    Attributes:
        e: position error x_d - x, m.
        e_dot: velocity error -x_dot, m/s.
        damping: D, N s/m.
        force_ref: F_ref, N. force_min, force_max: F_min, F_max, N.
        stiffness_min, stiffness_max: K_min, K_max, N/m.
        q_weight, r_weight: Q, R.
        tank_a: e * e_dot, the tank rows' normal.
        tank_lb_energy, tank_lb_power: the two rows' lower bounds (floats).
    """

    e: tuple
    e_dot: tuple
    damping: tuple
    force_ref: tuple
    force_min: tuple
    force_max: tuple
    stiffness_min: tuple
    stiffness_max: tuple
    q_weight: tuple
    r_weight: tuple
    tank_a: tuple
    tank_lb_energy: float
    tank_lb_power: float


class StiffnessQpSolution(NamedTuple):
    """Answer of one solve.

    Attributes:
        stiffness: k (3,), N/m; K_min when ``success`` is False.
        success: the solver reported an optimum of a feasible problem.
        active: bit mask of active constraints (:func:`active_constraint_names`).
        solve_time_s: wall time of the solve, s.
        status: "optimal", "infeasible" or the solver's failure name.
    """

    stiffness: tuple
    success: bool
    active: int
    solve_time_s: float
    status: str


def make_stiffness_qp_problem(
    e,
    e_dot,
    damping,
    force_ref,
    force_min,
    energy_J: float,
    dt: float,
    qp: StiffnessQpParams,
    tank: TankParams,
    force_max=None,
) -> StiffnessQpProblem:
    """Assembles one tick's QP from measurements, references and the tank.

    Args:
        e: x_d - x (3,), m. e_dot: -x_dot (3,), m/s.
        damping: D (3,), N s/m, from the previous tick's stiffness.
        force_ref: F_ref (3,), N. force_min: F_min (3,), N.
        energy_J: tank energy before the tick, J. dt: tick duration, s.
        qp, tank: parameters (K bounds, weights, F_max, T_min, eta).
        force_max: F_max (3,), N; default ``qp.force_max_N``.
    """
    e0, e1, e2 = float(e[0]), float(e[1]), float(e[2])
    v0, v1, v2 = float(e_dot[0]), float(e_dot[1]), float(e_dot[2])
    d0, d1, d2 = float(damping[0]), float(damping[1]), float(damping[2])
    k_min = qp.stiffness_min_N_per_m
    # The tank rows (vic_drake.control.tank.tank_qp_rows), inlined for speed.
    sigma = 0.0 if energy_J >= tank.max_energy_J else 1.0
    a = (e0 * v0, e1 * v1, e2 * v2)
    base = a[0] * k_min[0] + a[1] * k_min[1] + a[2] * k_min[2]
    base -= sigma * (d0 * v0 * v0 + d1 * v1 * v1 + d2 * v2 * v2)
    lb_energy = base + (tank.min_energy_J - energy_J) / dt if dt > 0.0 else -math.inf
    f_max = qp.force_max_N if force_max is None else force_max
    return StiffnessQpProblem(
        (e0, e1, e2),
        (v0, v1, v2),
        (d0, d1, d2),
        (float(force_ref[0]), float(force_ref[1]), float(force_ref[2])),
        (float(force_min[0]), float(force_min[1]), float(force_min[2])),
        (float(f_max[0]), float(f_max[1]), float(f_max[2])),
        (float(k_min[0]), float(k_min[1]), float(k_min[2])),
        tuple(qp.stiffness_max_N_per_m),
        tuple(qp.q_weight),
        tuple(qp.r_weight),
        a,
        lb_energy,
        base + tank.power_limit_W,
    )


def stiffness_qp_cost(problem: StiffnessQpProblem, k) -> float:
    """The QP cost at k (without the paper's factor 1/2)."""
    p = problem
    return sum(
        p.q_weight[i]
        * (p.e[i] * k[i] + p.damping[i] * p.e_dot[i] - p.force_ref[i]) ** 2
        + p.r_weight[i] * (k[i] - p.stiffness_min[i]) ** 2
        for i in range(3)
    )


def stiffness_qp_violation(problem: StiffnessQpProblem, k) -> dict[str, float]:
    """Largest violation of each constraint family at k (0 = satisfied)."""
    p = problem
    bound = force = 0.0
    for i in range(3):
        bound = max(bound, p.stiffness_min[i] - k[i], k[i] - p.stiffness_max[i])
        f = p.e[i] * k[i] + p.damping[i] * p.e_dot[i]
        force = max(force, p.force_min[i] - f, f - p.force_max[i])
    ak = sum(p.tank_a[i] * k[i] for i in range(3))
    return {
        "bounds_N_per_m": max(bound, 0.0),
        "force_N": max(force, 0.0),
        "tank_energy_W": max(p.tank_lb_energy - ak, 0.0),
        "tank_power_W": max(p.tank_lb_power - ak, 0.0),
    }


def fallback_solution(
    problem: StiffnessQpProblem, t0: float, status: str
) -> StiffnessQpSolution:
    """K_min with success=False and the given status; t0 from time.perf_counter()."""
    return StiffnessQpSolution(
        tuple(problem.stiffness_min), False, 0, time.perf_counter() - t0, status
    )
