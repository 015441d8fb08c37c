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


def active_constraints(problem: StiffnessQpProblem, k, *, rtol: float = 1e-6) -> int:
    """Mask of the constraints active at k, within rtol of each row's scale."""
    (e, ed, d, _, fmn, fmx, kmn, kmx, _, _, a, lb_energy, lb_power) = problem
    mask = 0
    bit = 1
    for i in range(3):
        ki = k[i]
        kt = rtol * (kmx[i] if kmx[i] > 1.0 else 1.0)
        if ki - kmn[i] <= kt:
            mask |= bit
        if kmx[i] - ki <= kt:
            mask |= bit << 1
        if e[i] != 0.0:
            f = e[i] * ki + d[i] * ed[i]
            ft = rtol * max(1.0, abs(fmx[i]), abs(fmn[i]))
            if f - fmn[i] <= ft:
                mask |= bit << 2
            if fmx[i] - f <= ft:
                mask |= bit << 3
        bit <<= 4
    ak = a[0] * k[0] + a[1] * k[1] + a[2] * k[2]
    scale = max(abs(a[0]), abs(a[1]), abs(a[2])) * max(kmx)
    if scale > 0.0:
        tt = rtol * max(scale, 1e-12)
        if ak - lb_energy <= tt:  # -inf (no dt) is never active.
            mask |= ACTIVE_TANK_ENERGY
        if ak - lb_power <= tt:
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
    (e, ed, d, fr, fmn, fmx, kmn, kmx, qw, rw, a, lb_energy, lb_power) = problem
    lo = []
    hi = []
    lo_bit = []
    hi_bit = []
    free = []
    curv = []  # 2 (Q e^2 + R): d^2 cost / dk^2.
    bit = 1
    # Per axis: the bound and force rows make one interval [lo, hi]; the
    # unconstrained minimiser is `free`.
    for ei, edi, di, fri, fmin, fmax, kmin, kmax, q, r in zip(
        e, ed, d, fr, fmn, fmx, kmn, kmx, qw, rw
    ):
        dv = di * edi
        lo_i, hi_i = kmin, kmax
        lb_i, hb_i = bit, bit << 1
        fmin_i, fmax_i = fmin - dv, fmax - dv
        if ei > 0.0:
            f_lo, f_hi = fmin_i / ei, fmax_i / ei
            if f_lo > lo_i:
                lo_i, lb_i = f_lo, bit << 2
            if f_hi < hi_i:
                hi_i, hb_i = f_hi, bit << 3
        elif ei < 0.0:
            f_lo, f_hi = fmax_i / ei, fmin_i / ei
            if f_lo > lo_i:
                lo_i, lb_i = f_lo, bit << 3
            if f_hi < hi_i:
                hi_i, hb_i = f_hi, bit << 2
        elif fmin_i > feas_tol * max(1.0, abs(fmin)) or fmax_i < -feas_tol * max(
            1.0, abs(fmax)
        ):
            return _fallback(problem, t0, "infeasible")
        if lo_i > hi_i:
            if lo_i - hi_i > feas_tol * max(1.0, abs(hi_i)):
                return _fallback(problem, t0, "infeasible")
            hi_i = lo_i
        lo.append(lo_i)
        hi.append(hi_i)
        lo_bit.append(lb_i)
        hi_bit.append(hb_i)
        h = q * ei * ei + r
        curv.append(2.0 * h)
        free.append((q * ei * (fri - dv) + r * kmin) / h)
        bit <<= 4

    # mu = 0: clip the free minimiser to the box.
    k = [
        lo_i if v < lo_i else (hi_i if v > hi_i else v)
        for v, lo_i, hi_i in zip(free, lo, hi)
    ]
    g = a[0] * k[0] + a[1] * k[1] + a[2] * k[2]
    lb = lb_energy if lb_energy > lb_power else lb_power
    mu = 0.0
    if g < lb:
        # The tank row is active. k(mu) = clip(free + mu a / curv, lo, hi) and
        # a' k(mu) is piecewise linear and nondecreasing: walk its breakpoints.
        def at(mu_: float) -> tuple[list[float], float]:
            k_ = [0.0, 0.0, 0.0]
            g_ = 0.0
            for i in range(3):
                v = free[i] + mu_ * a[i] / curv[i]
                k_[i] = lo[i] if v < lo[i] else (hi[i] if v > hi[i] else v)
                g_ += a[i] * k_[i]
            return k_, g_

        best = 0.0
        scale = 0.0
        for i in range(3):
            best += a[i] * (hi[i] if a[i] > 0.0 else lo[i])
            scale += abs(a[i]) * max(abs(hi[i]), 1.0)
        if best < lb - feas_tol * max(scale, abs(lb), 1e-12):
            return _fallback(problem, t0, "infeasible")
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
            m_hit = g_hit = None
            for m in breaks:
                _, g_m = at(m)
                if g_m >= lb:
                    m_hit, g_hit = m, g_m
                    break
                m_prev, g_prev = m, g_m
            if m_hit is None:  # Only reachable by rounding: all variables clipped.
                mu = m_prev
            else:
                mu = m_prev + (lb - g_prev) * (m_hit - m_prev) / (g_hit - g_prev)
            k, g = at(mu)
    active = 0
    for i in range(3):
        if k[i] <= lo[i]:
            active |= lo_bit[i]
        if k[i] >= hi[i]:
            active |= hi_bit[i]
    if mu > 0.0:
        active |= ACTIVE_TANK_ENERGY if lb_energy >= lb_power else 0
        active |= ACTIVE_TANK_POWER if lb_power >= lb_energy else 0
    return StiffnessQpSolution(
        (k[0], k[1], k[2]), True, active, time.perf_counter() - t0, "optimal"
    )


class StiffnessQp:
    """The stiffness QP as a Drake MathematicalProgram, built once.

    The program has one quadratic cost and one 8-row linear constraint
    binding over the (scaled) stiffness kk:

        rows 0-2  K_min_i <= k_i <= K_max_i             (stiffness bounds, as kk_i)
        rows 3-5  F_min_i - D_i e_dot_i <= e_i k_i <= F_max_i - D_i e_dot_i
        row  6    a' k >= lb_energy                     (tank energy, T+ >= T_min)
        row  7    a' k >= lb_power                      (power valve, dT/dt >= eta)

    Each :meth:`solve` updates both bindings in place (two
    ``UpdateCoefficients`` calls; the bounds live in the same binding as the
    rows because OSQP and Clarabel take every bound as a row anyway, and one
    update costs ~5 us) and calls the chosen solver. A row that holds over
    the whole box K_min <= k <= K_max is relaxed to (-inf, inf): it cannot be
    active, and interior-point Clarabel fails on near-zero rows such as
    1e-12 k >= c that a vanishing error produces.

    Scaling. For OSQP every force row and the tank rows are scaled to unit
    coefficients (the tank rows' a' k has coefficients ~1e-4: OSQP then hit
    its iteration limit on such cases, found by the property tests), and
    the decision variables are k scaled per axis,
    kk_i = k_i sqrt(2 (Q_i e_i^2 + R_i)), so that the cost's Hessian is the
    identity: in N/m (or uniformly in kN/m) the curvature ranges over 1e-5
    to 1 between axes (R = 1e-5, e_i from 0 to 2 cm) and OSQP's ADMM stops
    early along the flat axes (errors up to 0.3 N/m, measured). Clarabel
    (interior point, its own equilibration) is more accurate with k in kN/m
    and the cost normalised by its largest curvature (measured: max 1e-4
    N/m against the exact solver on the real logs vs ~1 N/m with the
    per-axis scaling). Measured on random problems (bounds, force and tank
    rows active in all combinations, R from 1e-5 to 10): OSQP (eps 1e-12, no
    polishing) within 2e-7 N/m of the exact answer (3,000 problems);
    Clarabel within 0.43 N/m (5,000 problems), the worst cases
    being flat axes (R = 1e-5, e_i ~ 0) whose optimum sits on a bound with a
    zero multiplier, which the interior point approaches only loosely.

    Args:
        solver: "osqp", "clarabel" or "exact" (the latter skips the program
            and calls :func:`solve_stiffness_qp_exact`).
        osqp_eps: OSQP's eps_abs and eps_rel.
    """

    def __init__(self, solver: str = "osqp", *, osqp_eps: float = 1e-12):
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
        kk = prog.NewContinuousVariables(3, "k_scaled")
        self._prog = prog
        self._cost = prog.AddQuadraticCost(np.eye(3), np.zeros(3), kk, is_convex=True)
        self._rows = prog.AddLinearConstraint(
            np.vstack([np.eye(3), np.eye(3), np.ones((2, 3))]),
            np.full(8, -np.inf),
            np.full(8, np.inf),
            kk,
        )
        self._rows.evaluator().set_description(
            "stiffness bounds, force rows, tank rows"
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
                # Re-estimate rho every 25 iterations rather than by timing:
                # ~25 % fewer iterations here (measured on the real logs).
                ("adaptive_rho_interval", 25),
                ("polishing", 0),  # Its notes go to stdout; eps 1e-12 suffices.
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
        self._A = np.zeros((8, 3))

    @property
    def prog(self):
        """The MathematicalProgram (None for the exact solver)."""
        return getattr(self, "_prog", None)

    def solve(self, problem: StiffnessQpProblem, *, guess=None) -> StiffnessQpSolution:
        """Solves one tick's QP; K_min with success=False on failure.

        Args:
            problem: the tick's numbers.
            guess: optional stiffness (3,), N/m, to warm-start from, e.g. the
                previous tick's answer (the caller keeps it, in its Context).
                OSQP uses it (measured: ~175 -> ~50 ADMM iterations, about
                half the solve time); Clarabel and the exact solver ignore it.
        """
        if self.solver_name == "exact":
            return solve_stiffness_qp_exact(problem)
        t0 = time.perf_counter()
        (e, ed, d, fr, fmn, fmx, kmn, kmx, qw, rw, a, lb_energy, lb_power) = problem
        inf = math.inf
        Q, A = self._Q, self._A
        lb = [0.0] * 8
        ub = [0.0] * 8
        b = [0.0, 0.0, 0.0]
        scale = [1e3, 1e3, 1e3]
        a_low = 0.0  # min of a' k over the box.
        for i in range(3):
            ei = e[i]
            h = qw[i] * ei * ei + rw[i]
            dv = d[i] * ed[i]
            # cost_i = h k^2 - 2 (Q e (F_ref - D e_dot) + R K_min) k + const, k = s kk.
            s = 1.0 / math.sqrt(2.0 * h) if self._unit_hessian else 1e3
            scale[i] = s
            Q[i, i] = 2.0 * h * s * s
            b[i] = -2.0 * (qw[i] * ei * (fr[i] - dv) + rw[i] * kmn[i]) * s
            A[i, i] = 1.0
            lb[i], ub[i] = kmn[i] / s, kmx[i] / s
            f_lo_row, f_hi_row = fmn[i] - dv, fmx[i] - dv
            f_lo = ei * (kmn[i] if ei > 0.0 else kmx[i])
            f_hi = ei * (kmx[i] if ei > 0.0 else kmn[i])
            if f_lo_row <= f_lo and f_hi <= f_hi_row:  # Redundant over the box.
                A[3 + i, i], lb[3 + i], ub[3 + i] = 0.0, -inf, inf
            elif ei == 0.0:  # 0 in [F_min - D e_dot, F_max - D e_dot] fails.
                return _fallback(problem, t0, "infeasible")
            elif self._unit_hessian:  # OSQP: e s kk in [lo, hi] divided by |e s|.
                c = abs(ei * s)
                A[3 + i, i] = 1.0 if ei > 0.0 else -1.0
                lb[3 + i], ub[3 + i] = f_lo_row / c, f_hi_row / c
            else:
                A[3 + i, i], lb[3 + i], ub[3 + i] = ei * s, f_lo_row, f_hi_row
            A[6, i] = A[7, i] = a[i] * s
            a_low += a[i] * (kmn[i] if a[i] > 0.0 else kmx[i])
        # Unit-norm tank rows (a' k ~ 1e-4 k otherwise: ADMM then stalls).
        norm = math.sqrt(A[6, 0] ** 2 + A[6, 1] ** 2 + A[6, 2] ** 2)
        if norm > 0.0 and self._unit_hessian:
            A[6] /= norm
            A[7] /= norm
        else:
            norm = 1.0
        lb[6] = lb_energy / norm if lb_energy > a_low else -inf
        lb[7] = lb_power / norm if lb_power > a_low else -inf
        ub[6] = ub[7] = inf
        if self._unit_hessian:
            self._cost.evaluator().UpdateCoefficients(Q, np.array(b))
        else:  # Normalise (the scale does not move the optimum).
            c = 1.0 / max(Q[0, 0], Q[1, 1], Q[2, 2])
            self._cost.evaluator().UpdateCoefficients(Q * c, np.array(b) * c)
        self._rows.evaluator().UpdateCoefficients(A, np.array(lb), np.array(ub))
        x0 = None
        if guess is not None and self._unit_hessian:
            x0 = np.array(
                [guess[0] / scale[0], guess[1] / scale[1], guess[2] / scale[2]]
            )
        result = self._solver.Solve(self._prog, x0, self._options)
        if not result.is_success():
            return _fallback(
                problem, t0, str(result.get_solution_result()).split(".")[-1]
            )
        kk = result.get_x_val()
        k = (float(kk[0]) * scale[0], float(kk[1]) * scale[1], float(kk[2]) * scale[2])
        if not (math.isfinite(k[0]) and math.isfinite(k[1]) and math.isfinite(k[2])):
            return _fallback(problem, t0, "non_finite")
        return StiffnessQpSolution(
            k, True, active_constraints(problem, k), time.perf_counter() - t0, "optimal"
        )
