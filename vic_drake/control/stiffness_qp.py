"""The per-tick stiffness QP (eq. 8 of the paper, diagonal form).

In the diagonal stiffness k = (k_x, k_y, k_z), N/m, with the position error
e = x_d - x, velocity error e_dot = -x_dot, damping D (from the previous
tick's stiffness), desired force F_ref and force bounds F_min, F_max (sensor
convention: negative z = pressing into the body):

    min_k  sum_i Q_i (e_i k_i + D_i e_dot_i - F_ref_i)^2 + R_i (k_i - K_min_i)^2
    s.t.   K_min <= k <= K_max
           F_min <= e_i k_i + D_i e_dot_i <= F_max           (per axis)
           a' k >= lb_energy,  a' k >= lb_power              (tank rows,
                                                 see vic_drake.control.tank)

Two solvers give the same answer:

- :func:`solve_stiffness_qp_exact`: the cost is separable, the bound and
  force rows are per-axis intervals and both tank rows share the same
  normal a = e * e_dot, so the QP is a separable strictly convex quadratic on
  a box with one linear inequality. Its KKT conditions give
  k(mu) = clip(k_free + mu a / (2 (Q e^2 + R)), lo, hi), and a' k(mu) is
  piecewise linear and nondecreasing in the multiplier mu >= 0; the exact
  optimum is found by walking the <= 6 breakpoints. Plain floats, no numpy:
  a few microseconds. Used as the test oracle and the default fast path.
- :class:`StiffnessQp`: a Drake ``MathematicalProgram`` built once (cost,
  bounding box, 3 force rows, 2 tank rows) whose coefficients are updated in
  place each tick, solved by OSQP or Clarabel (or forwarding to the exact
  solver). k is scaled to kN/m inside the program for OSQP's conditioning.

A failed or infeasible solve returns K_min with ``success=False``; callers
count these (the LeafSystem keeps the count in its state).
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np

from vic_drake.control.params import StiffnessQpParams, TankParams
from vic_drake.control.tank import tank_qp_rows
from vic_drake.errors import VicDrakeError

AXES = ("x", "y", "z")
_KINDS = ("k_min", "k_max", "f_min", "f_max")
#: Bit of the active-constraint mask for (kind, axis): 1 << (4 * axis + kind).
ACTIVE_TANK_ENERGY = 1 << 12
ACTIVE_TANK_POWER = 1 << 13


def active_bit(kind: str, axis: int) -> int:
    """The mask bit of a per-axis constraint kind ('k_min', 'k_max', 'f_min', 'f_max')."""
    return 1 << (4 * axis + _KINDS.index(kind))


def active_constraint_names(mask: int) -> list[str]:
    """Names of the constraints in an active mask, e.g. ['k_min_x', 'tank_energy']."""
    names = [
        f"{kind}_{AXES[axis]}"
        for axis in range(3)
        for k, kind in enumerate(_KINDS)
        if mask & (1 << (4 * axis + k))
    ]
    if mask & ACTIVE_TANK_ENERGY:
        names.append("tank_energy")
    if mask & ACTIVE_TANK_POWER:
        names.append("tank_power")
    return names


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
    e = (float(e[0]), float(e[1]), float(e[2]))
    e_dot = (float(e_dot[0]), float(e_dot[1]), float(e_dot[2]))
    damping = (float(damping[0]), float(damping[1]), float(damping[2]))
    k_min = tuple(qp.stiffness_min_N_per_m)
    a, lb_energy, lb_power = tank_qp_rows(energy_J, e, e_dot, k_min, damping, dt, tank)
    return StiffnessQpProblem(
        e=e,
        e_dot=e_dot,
        damping=damping,
        force_ref=(float(force_ref[0]), float(force_ref[1]), float(force_ref[2])),
        force_min=(float(force_min[0]), float(force_min[1]), float(force_min[2])),
        force_max=tuple(qp.force_max_N)
        if force_max is None
        else tuple(map(float, force_max)),
        stiffness_min=k_min,
        stiffness_max=tuple(qp.stiffness_max_N_per_m),
        q_weight=tuple(qp.q_weight),
        r_weight=tuple(qp.r_weight),
        tank_a=a,
        tank_lb_energy=lb_energy,
        tank_lb_power=lb_power,
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


def active_constraints(problem: StiffnessQpProblem, k, *, rtol: float = 1e-6) -> int:
    """Mask of the constraints active at k, within rtol of each row's scale."""
    p = problem
    mask = 0
    for i in range(3):
        kt = rtol * max(1.0, abs(p.stiffness_max[i]))
        if k[i] - p.stiffness_min[i] <= kt:
            mask |= 1 << (4 * i)
        if p.stiffness_max[i] - k[i] <= kt:
            mask |= 1 << (4 * i + 1)
        if p.e[i] != 0.0:
            f = p.e[i] * k[i] + p.damping[i] * p.e_dot[i]
            ft = rtol * max(1.0, abs(p.force_max[i]), abs(p.force_min[i]))
            if f - p.force_min[i] <= ft:
                mask |= 1 << (4 * i + 2)
            if p.force_max[i] - f <= ft:
                mask |= 1 << (4 * i + 3)
    ak = p.tank_a[0] * k[0] + p.tank_a[1] * k[1] + p.tank_a[2] * k[2]
    scale = max(abs(p.tank_a[0]), abs(p.tank_a[1]), abs(p.tank_a[2])) * max(
        p.stiffness_max
    )
    tt = rtol * max(scale, 1e-12)
    if math.isfinite(p.tank_lb_energy) and ak - p.tank_lb_energy <= tt and scale > 0:
        mask |= ACTIVE_TANK_ENERGY
    if ak - p.tank_lb_power <= tt and scale > 0:
        mask |= ACTIVE_TANK_POWER
    return mask


def _fallback(
    problem: StiffnessQpProblem, t0: float, status: str
) -> StiffnessQpSolution:
    return StiffnessQpSolution(
        tuple(problem.stiffness_min), False, 0, time.perf_counter() - t0, status
    )


def solve_stiffness_qp_exact(
    problem: StiffnessQpProblem, *, feas_tol: float = 1e-9
) -> StiffnessQpSolution:
    """Exact solution of the stiffness QP (closed form on the KKT conditions).

    Args:
        problem: one tick's QP (R > 0 on every axis, so it is strictly convex).
        feas_tol: tolerance on the per-axis interval and tank-row
            feasibility, relative to each row's scale.

    Returns:
        The unique optimum, or K_min with success=False and status
        "infeasible" when the constraints cannot all hold.
    """
    t0 = time.perf_counter()
    p = problem
    e, ed, d, fr = p.e, p.e_dot, p.damping, p.force_ref
    lo = [0.0, 0.0, 0.0]
    hi = [0.0, 0.0, 0.0]
    lo_bit = [0, 0, 0]
    hi_bit = [0, 0, 0]
    free = [0.0, 0.0, 0.0]
    curv = [0.0, 0.0, 0.0]  # 2 (Q e^2 + R): d^2 cost / dk^2.
    for i in range(3):
        ei = e[i]
        kmin = p.stiffness_min[i]
        kmax = p.stiffness_max[i]
        q = p.q_weight[i]
        r = p.r_weight[i]
        dv = d[i] * ed[i]
        lo_i, hi_i = kmin, kmax
        lb_i, hb_i = 1 << (4 * i), 1 << (4 * i + 1)
        fmin_i, fmax_i = p.force_min[i] - dv, p.force_max[i] - dv
        if ei > 0.0:
            a, b = fmin_i / ei, fmax_i / ei
            if a > lo_i:
                lo_i, lb_i = a, 1 << (4 * i + 2)
            if b < hi_i:
                hi_i, hb_i = b, 1 << (4 * i + 3)
        elif ei < 0.0:
            a, b = fmax_i / ei, fmin_i / ei
            if a > lo_i:
                lo_i, lb_i = a, 1 << (4 * i + 3)
            if b < hi_i:
                hi_i, hb_i = b, 1 << (4 * i + 2)
        elif fmin_i > feas_tol * max(
            1.0, abs(p.force_min[i])
        ) or fmax_i < -feas_tol * max(1.0, abs(p.force_max[i])):
            return _fallback(p, t0, "infeasible")
        if lo_i > hi_i:
            if lo_i - hi_i > feas_tol * max(1.0, abs(hi_i)):
                return _fallback(p, t0, "infeasible")
            hi_i = lo_i
        lo[i], hi[i], lo_bit[i], hi_bit[i] = lo_i, hi_i, lb_i, hb_i
        h = q * ei * ei + r
        curv[i] = 2.0 * h
        free[i] = (q * ei * (fr[i] - dv) + r * kmin) / h

    a = p.tank_a
    lb = p.tank_lb_energy if p.tank_lb_energy > p.tank_lb_power else p.tank_lb_power

    def at(mu: float) -> tuple[list[float], float]:
        k = [0.0, 0.0, 0.0]
        g = 0.0
        for i in range(3):
            v = free[i] + mu * a[i] / curv[i]
            k[i] = lo[i] if v < lo[i] else (hi[i] if v > hi[i] else v)
            g += a[i] * k[i]
        return k, g

    k, g = at(0.0)
    mu = 0.0
    if g < lb:
        # The tank row is active: find mu > 0 with a' k(mu) = lb.
        best = 0.0
        for i in range(3):
            best += a[i] * (hi[i] if a[i] > 0.0 else lo[i])
        scale = (
            abs(a[0]) * max(abs(hi[0]), 1.0)
            + abs(a[1]) * max(abs(hi[1]), 1.0)
            + abs(a[2]) * max(abs(hi[2]), 1.0)
        )
        if best < lb - feas_tol * max(scale, abs(lb), 1e-12):
            return _fallback(p, t0, "infeasible")
        if best <= lb:
            mu = math.inf
            k = [
                hi[i] if a[i] > 0.0 else (lo[i] if a[i] < 0.0 else k[i])
                for i in range(3)
            ]
        else:
            breaks = []
            for i in range(3):
                if a[i] != 0.0:
                    s = curv[i] / a[i]
                    for bound in (lo[i], hi[i]):
                        m = (bound - free[i]) * s
                        if m > 0.0:
                            breaks.append(m)
            breaks.sort()
            m_prev, g_prev = 0.0, g
            for m in breaks:
                k_m, g_m = at(m)
                if g_m >= lb:
                    break
                m_prev, g_prev = m, g_m
            else:
                m = None
            if m is None:  # Only reachable by rounding: all variables clipped.
                k, g = at(m_prev)
                mu = m_prev
            else:
                mu = m_prev + (lb - g_prev) * (m - m_prev) / (g_m - g_prev)
                k, g = at(mu)
    active = 0
    for i in range(3):
        if k[i] <= lo[i]:
            active |= lo_bit[i]
        if k[i] >= hi[i]:
            active |= hi_bit[i]
    if mu > 0.0:
        active |= ACTIVE_TANK_ENERGY if p.tank_lb_energy >= p.tank_lb_power else 0
        active |= ACTIVE_TANK_POWER if p.tank_lb_power >= p.tank_lb_energy else 0
    return StiffnessQpSolution(
        (k[0], k[1], k[2]), True, active, time.perf_counter() - t0, "optimal"
    )


class StiffnessQp:
    """The stiffness QP as a Drake MathematicalProgram, built once.

    Each :meth:`solve` updates the cost, the bounding box, the force rows and
    the tank rows in place (``UpdateCoefficients`` / ``set_bounds``) and calls
    the chosen solver. For OSQP the decision variables are k scaled per axis,
    kk_i = k_i sqrt(2 (Q_i e_i^2 + R_i)), so that the cost's Hessian is the
    identity: in N/m (or uniformly in kN/m) the curvature ranges over 1e-5
    to 1 between axes (R = 1e-5, e_i from 0 to 2 cm) and OSQP's ADMM stops
    early along the flat axes (errors up to 0.3 N/m, measured). Clarabel
    (interior point, its own equilibration) is more accurate with k in kN/m
    and the cost normalised by its largest curvature (measured: max 1e-4
    N/m against the exact solver vs ~1 N/m with the per-axis scaling).

    Args:
        solver: "osqp", "clarabel" or "exact" (the latter skips the program).
        osqp_eps: OSQP's eps_abs and eps_rel.
    """

    def __init__(self, solver: str = "osqp", *, osqp_eps: float = 1e-9):
        from pydrake.solvers import (
            ClarabelSolver,
            MathematicalProgram,
            OsqpSolver,
            SolverOptions,
        )

        if solver not in ("osqp", "clarabel", "exact"):
            raise VicDrakeError(
                f"stiffness QP solver must be 'osqp', 'clarabel' or 'exact'; got {solver!r}"
            )
        self.solver_name = solver
        if solver == "exact":
            return
        prog = MathematicalProgram()
        kk = prog.NewContinuousVariables(3, "k_kN_per_m")
        self._prog = prog
        self._cost = prog.AddQuadraticCost(np.eye(3), np.zeros(3), kk, is_convex=True)
        self._box = prog.AddBoundingBoxConstraint(np.zeros(3), np.ones(3), kk)
        self._force = prog.AddLinearConstraint(np.eye(3), -np.ones(3), np.ones(3), kk)
        self._tank = prog.AddLinearConstraint(
            np.ones((2, 3)), np.full(2, -np.inf), np.full(2, np.inf), kk
        )
        self._options = SolverOptions()
        if solver == "osqp":
            self._solver = OsqpSolver()
            sid = OsqpSolver.id()
            for name, value in (
                ("eps_abs", osqp_eps),
                ("eps_rel", osqp_eps),
                ("eps_prim_inf", 1e-12),
                ("eps_dual_inf", 1e-12),
                ("max_iter", 20000),
                ("polishing", 1),
                ("verbose", 0),
            ):
                self._options.SetOption(sid, name, value)
        else:
            self._solver = ClarabelSolver()
            sid = ClarabelSolver.id()
            for name in ("tol_gap_abs", "tol_gap_rel", "tol_feas", "tol_ktratio"):
                self._options.SetOption(sid, name, 1e-12)
        if not self._solver.available() or not self._solver.enabled():
            raise VicDrakeError(
                f"the {solver} solver is not available in this Drake build"
            )
        self._unit_hessian = solver == "osqp"
        self._Q = np.zeros((3, 3))
        self._b = np.zeros(3)
        self._A_force = np.zeros((3, 3))
        self._A_tank = np.zeros((2, 3))
        self._guess = np.zeros(3)

    @property
    def prog(self):
        """The MathematicalProgram (None for the exact solver)."""
        return getattr(self, "_prog", None)

    def solve(self, problem: StiffnessQpProblem) -> StiffnessQpSolution:
        """Solves one tick's QP; K_min with success=False on failure."""
        if self.solver_name == "exact":
            return solve_stiffness_qp_exact(problem)
        t0 = time.perf_counter()
        p = problem
        Q, b, A_f, A_t = self._Q, self._b, self._A_force, self._A_tank
        lb_f = np.empty(3)
        ub_f = np.empty(3)
        lb_k = np.empty(3)
        ub_k = np.empty(3)
        scale = [1.0, 1.0, 1.0]
        for i in range(3):
            e = p.e[i]
            h = p.q_weight[i] * e * e + p.r_weight[i]
            dv = p.damping[i] * p.e_dot[i]
            # cost_i = h k^2 - 2 (Q e (F_ref - D e_dot) + R K_min) k + const. With
            # k = s kk and s = 1 / sqrt(2 h) the Hessian in kk is the identity.
            s = 1.0 / math.sqrt(2.0 * h) if self._unit_hessian else 1e3
            scale[i] = s
            Q[i, i] = 2.0 * h * s * s
            b[i] = (
                -2.0
                * (
                    p.q_weight[i] * e * (p.force_ref[i] - dv)
                    + p.r_weight[i] * p.stiffness_min[i]
                )
                * s
            )
            lb_f[i] = p.force_min[i] - dv
            ub_f[i] = p.force_max[i] - dv
            f_lo = e * (p.stiffness_min[i] if e > 0.0 else p.stiffness_max[i])
            f_hi = e * (p.stiffness_max[i] if e > 0.0 else p.stiffness_min[i])
            if lb_f[i] <= f_lo and f_hi <= ub_f[i]:
                # Redundant over the whole box: drop it. Interior-point solvers
                # fail on rows like 1e-12 k >= c that a small e produces.
                A_f[i, i], lb_f[i], ub_f[i] = 0.0, -np.inf, np.inf
            else:
                A_f[i, i] = e * s
            lb_k[i] = p.stiffness_min[i] / s
            ub_k[i] = p.stiffness_max[i] / s
            A_t[0, i] = A_t[1, i] = p.tank_a[i] * s
        if not self._unit_hessian:  # Normalise (the scale does not move the optimum).
            c = 1.0 / max(Q[0, 0], Q[1, 1], Q[2, 2])
            Q *= c
            b *= c
        self._cost.evaluator().UpdateCoefficients(Q, b)
        self._box.evaluator().set_bounds(lb_k, ub_k)
        self._force.evaluator().UpdateCoefficients(A_f, lb_f, ub_f)
        # The tank rows share a' k; drop each one that holds over the whole box.
        a_low = 0.0
        for i in range(3):
            a_i = p.tank_a[i]
            a_low += a_i * (p.stiffness_min[i] if a_i > 0.0 else p.stiffness_max[i])
        lb_t = np.array(
            [
                p.tank_lb_energy if p.tank_lb_energy > a_low else -np.inf,
                p.tank_lb_power if p.tank_lb_power > a_low else -np.inf,
            ]
        )
        self._tank.evaluator().UpdateCoefficients(A_t, lb_t, np.full(2, np.inf))
        result = self._solver.Solve(self._prog, None, self._options)
        if not result.is_success():
            return _fallback(p, t0, str(result.get_solution_result()).split(".")[-1])
        kk = result.get_x_val()
        k = (float(kk[0]) * scale[0], float(kk[1]) * scale[1], float(kk[2]) * scale[2])
        if not all(math.isfinite(v) for v in k):
            return _fallback(p, t0, "non_finite")
        return StiffnessQpSolution(
            k, True, active_constraints(p, k), time.perf_counter() - t0, "optimal"
        )
