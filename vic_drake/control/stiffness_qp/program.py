"""The stiffness QP as a Drake MathematicalProgram, built once (OSQP or Clarabel).

The program (cost, bounding box, 3 force rows, 2 tank rows) is built in the
constructor; each tick :meth:`StiffnessQp.solve` updates its coefficients
in place and calls the chosen solver, or forwards to the exact solver of
:mod:`vic_drake.control.stiffness_qp.exact`.
"""

from __future__ import annotations

import math
import time

import numpy as np

from vic_drake.control.stiffness_qp.constraints import active_constraints
from vic_drake.control.stiffness_qp.exact import solve_stiffness_qp_exact
from vic_drake.control.stiffness_qp.problem import (
    StiffnessQpProblem,
    StiffnessQpSolution,
    fallback_solution,
)
from vic_drake.errors import VicDrakeError


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
    rows because OSQP and Clarabel take every bound as a row anyway) and
    calls the chosen solver. A row that holds over the whole box
    K_min <= k <= K_max is relaxed to (-inf, inf): it cannot be active, and
    interior-point Clarabel fails on near-zero rows such as 1e-12 k >= c
    that a vanishing error produces.

    Scaling. For OSQP every force row and the tank rows are scaled to unit
    coefficients (the tank rows' a' k has coefficients ~1e-4, on which OSQP
    hit its iteration limit), and the decision variables are k scaled per
    axis, kk_i = k_i sqrt(2 (Q_i e_i^2 + R_i)), so that the cost's Hessian is
    the identity: in N/m (or uniformly in kN/m) the curvature ranges over
    1e-5 to 1 between axes (R = 1e-5, e_i from 0 to 2 cm) and OSQP's ADMM
    stops early along the flat axes. Clarabel (interior point, its own
    equilibration) is run with k in kN/m and the cost normalised by its
    largest curvature. Accuracy of both against the exact solver: see
    docs/decisions.md, "Stiffness QP solvers and scaling".

    Args:
        solver: "osqp", "clarabel" or "exact" (the latter skips the program
            and calls :func:`solve_stiffness_qp_exact`).
        osqp_eps: OSQP's eps_abs and eps_rel.
    """

    def __init__(self, solver: str = "osqp", *, osqp_eps: float = 1e-12):
        # Local import: pydrake is a heavy dependency and control/ is pure math
        # (the exact solver and the problem need none of it).
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
                # Re-estimate rho every 25 iterations rather than by timing
                # (see docs/decisions.md, "OSQP settings").
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
                OSQP uses it (see docs/decisions.md, "OSQP settings");
                Clarabel and the exact solver ignore it.
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
                return fallback_solution(problem, t0, "infeasible")
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
            return fallback_solution(
                problem, t0, str(result.get_solution_result()).split(".")[-1]
            )
        kk = result.get_x_val()
        k = (float(kk[0]) * scale[0], float(kk[1]) * scale[1], float(kk[2]) * scale[2])
        if not (math.isfinite(k[0]) and math.isfinite(k[1]) and math.isfinite(k[2])):
            return fallback_solution(problem, t0, "non_finite")
        return StiffnessQpSolution(
            k, True, active_constraints(problem, k), time.perf_counter() - t0, "optimal"
        )
