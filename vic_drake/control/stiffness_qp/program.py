"""The stiffness QP as a Drake MathematicalProgram, built once and solved by a Drake solver.

The program (cost, bounding rows, 3 force rows, 2 tank rows) is built in the
constructor; each tick :meth:`StiffnessQp.solve` updates its coefficients
and bounds in place and calls the chosen solver, or forwards to the exact
solver of :mod:`vic_drake.control.stiffness_qp.exact`.
"""

from __future__ import annotations

import math
from time import perf_counter

import numpy as np

from vic_drake.control.stiffness_qp.constraints import active_constraints
from vic_drake.control.stiffness_qp.exact import (
    FEASIBILITY_TOL,
    axis_interval,
    solve_stiffness_qp_exact,
)
from vic_drake.control.stiffness_qp.problem import (
    StiffnessQpProblem,
    StiffnessQpSolution,
    fallback_solution,
)
from vic_drake.errors import VicDrakeError

#: The Drake solvers :class:`StiffnessQp` can run (each one of the pip wheel
#: of Drake that takes a convex quadratic cost with linear inequality rows).
#: Scenarios use "osqp" or "clarabel" (see StiffnessQpParams); the others are
#: here to be measured (benchmarks/bench_controller.py).
PROGRAM_SOLVERS = ("osqp", "clarabel", "scs", "clp", "nlopt", "snopt", "ipopt")

# The Drake solvers that start from the initial guess (Drake 1.51's OSQP and
# Clarabel wrappers ignore it).
_USES_GUESS = ("nlopt", "snopt", "ipopt")


def _solver_and_options(solver: str, osqp_eps: float):
    """The Drake solver object and its SolverOptions (built once)."""
    from pydrake import solvers

    classes = {
        "osqp": solvers.OsqpSolver,
        "clarabel": solvers.ClarabelSolver,
        "scs": solvers.ScsSolver,
        "clp": solvers.ClpSolver,
        "nlopt": solvers.NloptSolver,
        "snopt": solvers.SnoptSolver,
        "ipopt": solvers.IpoptSolver,
    }
    settings = {
        "osqp": {
            "eps_abs": osqp_eps,
            "eps_rel": osqp_eps,
            "eps_prim_inf": 1e-12,
            "eps_dual_inf": 1e-12,
            "max_iter": 20000,
            # The program is already scaled (unit Hessian, unit rows): no
            # equilibration; rho re-estimated and termination checked every
            # 10 iterations (see docs/decisions.md, "OSQP settings").
            "scaling": 0,
            "rho": 0.5,
            "adaptive_rho_interval": 10,
            "check_termination": 10,
            "polishing": 0,  # Polishing prints notes to stdout.
            "verbose": 0,
        },
        "clarabel": {
            name: 1e-12
            for name in ("tol_gap_abs", "tol_gap_rel", "tol_feas", "tol_ktratio")
        },
        "scs": {"eps_abs": 1e-9, "eps_rel": 1e-9},
        "clp": {},
        "nlopt": {},
        "snopt": {
            "Major optimality tolerance": 1e-12,
            "Major feasibility tolerance": 1e-12,
        },
        "ipopt": {"tol": 1e-12},
    }
    instance = classes[solver]()
    if not instance.available() or not instance.enabled():
        raise VicDrakeError(f"the {solver} solver is not available in this Drake build")
    options = solvers.SolverOptions()
    for name, value in settings[solver].items():
        options.SetOption(instance.solver_id(), name, value)
    return instance, options


class StiffnessQp:
    """The stiffness QP as a Drake MathematicalProgram, built once.

    The program has one quadratic cost and one 8-row linear constraint
    binding over the (scaled) stiffness kk, k_i = s_i kk_i:

        rows 0-2  K_min_i <= k_i <= K_max_i             (stiffness bounds)
        rows 3-5  F_min_i - D_i e_dot_i <= e_i k_i <= F_max_i - D_i e_dot_i
        row  6    a' k >= lb_energy                     (tank energy, T+ >= T_min)
        row  7    a' k >= lb_power                      (power valve, dT/dt >= eta)

    Every row is divided by its coefficient's scale: rows 0-5 read
    lo <= kk_i <= hi (a force row divided by e_i s_i, its bounds swapped
    when e_i < 0), so the matrix only changes in the tank rows, which are
    a' diag(s) / |a' diag(s)|. Each :meth:`solve` makes two calls into
    Drake before the solve (``UpdateCoefficients`` of the cost and of the
    rows) and reuses one ``MathematicalProgramResult``. A row that holds
    over the whole box K_min <= k <= K_max gets the bounds (-inf, inf)
    (+-1e20 for NLopt): it cannot be active, and interior-point Clarabel fails on near-zero rows
    such as 1e-12 k >= c that a vanishing error produces.

    Scaling. For every solver but Clarabel, s_i = 1 / sqrt(2 (Q_i e_i^2 +
    R_i)), so that the cost's Hessian is the identity: in N/m (or uniformly
    in kN/m) the curvature ranges over 1e-5 to 1 between axes (R = 1e-5,
    e_i from 0 to 2 cm) and OSQP's ADMM stops early along the flat axes.
    Clarabel (interior point, its own equilibration) is run with k in kN/m
    (s_i = 1e3) and the cost normalised by its largest curvature. Accuracy
    and cost of each solver against the exact solver: see docs/decisions.md,
    "Stiffness QP solvers and scaling" and "Stiffness QP solvers of the Drake
    1.51 wheel: cost and accuracy".

    Args:
        solver: one of :data:`PROGRAM_SOLVERS`, or "exact" (which skips the
            program and calls :func:`solve_stiffness_qp_exact`).
        osqp_eps: OSQP's eps_abs and eps_rel.
    """

    def __init__(self, solver: str = "osqp", *, osqp_eps: float = 1e-12):
        if solver != "exact" and solver not in PROGRAM_SOLVERS:
            names = ", ".join(repr(s) for s in PROGRAM_SOLVERS)
            raise VicDrakeError(
                f"stiffness QP solver must be 'exact' or a Drake solver ({names}); "
                f"got {solver!r}"
            )
        self.solver_name = solver
        if solver == "exact":
            return
        # Local import: pydrake is a heavy dependency and control/ is pure math
        # (the exact solver and the problem need none of it).
        from pydrake.solvers import MathematicalProgram, MathematicalProgramResult

        self._solver, self._options = _solver_and_options(solver, osqp_eps)
        prog = MathematicalProgram()
        kk = prog.NewContinuousVariables(3, "k_scaled")
        self._prog = prog
        self._eye = np.eye(3)
        self._cost = prog.AddQuadraticCost(self._eye, np.zeros(3), kk, is_convex=True)
        # Rows 0-5 stay the identity; solve() writes the tank rows 6-7.
        self._A = np.vstack([np.eye(3), np.eye(3), np.ones((2, 3))])
        self._rows = prog.AddLinearConstraint(
            self._A, np.full(8, -np.inf), np.full(8, np.inf), kk
        )
        self._rows.evaluator().set_description(
            "stiffness bounds, force rows, tank rows"
        )
        self._cost_evaluator = self._cost.evaluator()
        self._rows_evaluator = self._rows.evaluator()
        self._result = MathematicalProgramResult()
        self._unit_hessian = solver != "clarabel"
        self._uses_guess = solver in _USES_GUESS
        # NLopt fails (kSolverSpecificError) on a row whose two bounds are
        # infinite: it gets finite ones, far outside every row's range.
        self._free = 1e20 if solver == "nlopt" else math.inf

    @property
    def prog(self):
        """The MathematicalProgram (None for the exact solver)."""
        return getattr(self, "_prog", None)

    def solve(self, problem: StiffnessQpProblem, *, guess=None) -> StiffnessQpSolution:
        """Solves one tick's QP; K_min with success=False on failure.

        Args:
            problem: the tick's numbers.
            guess: optional stiffness (3,), N/m, e.g. the previous tick's
                answer: the initial guess of the solvers that use one
                (NLopt, SNOPT, IPOPT); OSQP, Clarabel, SCS, Clp and the exact
                solver ignore it.
        """
        if self.solver_name == "exact":
            return solve_stiffness_qp_exact(problem)
        t0 = perf_counter()
        (e, ed, d, fr, fmn, fmx, kmn, kmx, qw, rw, a, lb_energy, lb_power) = problem
        unit = self._unit_hessian
        free = self._free
        x = _axis_rows(e[0], ed[0], d[0], fr[0], fmn[0], fmx[0], kmn[0], kmx[0],
                       qw[0], rw[0], 1, unit, free)  # fmt: skip
        y = _axis_rows(e[1], ed[1], d[1], fr[1], fmn[1], fmx[1], kmn[1], kmx[1],
                       qw[1], rw[1], 1 << 4, unit, free)  # fmt: skip
        z = _axis_rows(e[2], ed[2], d[2], fr[2], fmn[2], fmx[2], kmn[2], kmx[2],
                       qw[2], rw[2], 1 << 8, unit, free)  # fmt: skip
        if x is None or y is None or z is None:  # A force row no K of the box meets.
            return fallback_solution(problem, t0, "infeasible")
        (s0, c0, b0, lo0, hi0, flo0, fhi0) = x
        (s1, c1, b1, lo1, hi1, flo1, fhi1) = y
        (s2, c2, b2, lo2, hi2, flo2, fhi2) = z
        a0, a1, a2 = a
        # Tank rows, unit norm (a' k ~ 1e-4 k otherwise: ADMM then stalls).
        ta0, ta1, ta2 = a0 * s0, a1 * s1, a2 * s2
        norm = math.sqrt(ta0 * ta0 + ta1 * ta1 + ta2 * ta2)
        if norm > 0.0:
            ta0, ta1, ta2 = ta0 / norm, ta1 / norm, ta2 / norm
        else:
            norm = 1.0
        # min of a' k over the box: a bound at or below it cannot be active.
        a_low = (
            a0 * (kmn[0] if a0 > 0.0 else kmx[0])
            + a1 * (kmn[1] if a1 > 0.0 else kmx[1])
            + a2 * (kmn[2] if a2 > 0.0 else kmx[2])
        )
        A = self._A
        A[6, 0] = A[7, 0] = ta0
        A[6, 1] = A[7, 1] = ta1
        A[6, 2] = A[7, 2] = ta2
        lb = np.array(
            [lo0, lo1, lo2, flo0, flo1, flo2,
             lb_energy / norm if lb_energy > a_low else -free,
             lb_power / norm if lb_power > a_low else -free]
        )  # fmt: skip
        ub = np.array([hi0, hi1, hi2, fhi0, fhi1, fhi2, free, free])
        if unit:
            self._cost_evaluator.UpdateCoefficients(
                self._eye, np.array([b0, b1, b2]), 0.0, True
            )
        else:  # Normalise (the scale does not move the optimum).
            c = 1.0 / max(c0, c1, c2)
            self._cost_evaluator.UpdateCoefficients(
                np.diag([c0 * c, c1 * c, c2 * c]), np.array([b0 * c, b1 * c, b2 * c]),
                0.0, True,
            )  # fmt: skip
        self._rows_evaluator.UpdateCoefficients(A, lb, ub)
        x0 = None
        if guess is not None and self._uses_guess:
            x0 = np.array([guess[0] / s0, guess[1] / s1, guess[2] / s2])
        result = self._result
        self._solver.Solve(self._prog, x0, self._options, result)
        if not result.is_success():
            return fallback_solution(
                problem, t0, str(result.get_solution_result()).split(".")[-1]
            )
        kk = result.get_x_val().tolist()
        k = (kk[0] * s0, kk[1] * s1, kk[2] * s2)
        if not (math.isfinite(k[0]) and math.isfinite(k[1]) and math.isfinite(k[2])):
            return fallback_solution(problem, t0, "non_finite")
        return StiffnessQpSolution(
            k, True, active_constraints(problem, k), perf_counter() - t0, "optimal"
        )


def _axis_rows(ei, edi, di, fri, fmin, fmax, kmin, kmax, q, r, bit, unit, free):
    """One axis of the scaled program, or None if its force row cannot hold.

    The interval, its feasibility and the unconstrained minimiser are the
    exact solver's (:func:`~vic_drake.control.stiffness_qp.exact.axis_interval`;
    bit: the axis' K_min bit). Returns (s, curv, b, lo, hi, f_lo, f_hi): the
    scale s (k = s kk), the cost's curvature in kk (1 when ``unit``) and
    linear coefficient b, the bounding row lo <= kk <= hi and the force row
    f_lo <= kk <= f_hi, whose side is (-)``free`` where the box is the
    tighter bound (a force row that holds over the whole box is (-free,
    free)).
    """
    axis = axis_interval(
        ei, edi, di, fri, fmin, fmax, kmin, kmax, q, r, bit, FEASIBILITY_TOL
    )
    if axis is None:
        return None
    lo, hi, lo_bit, hi_bit, k_free, curv = axis
    # cost = (curv / 2) k^2 - curv k_free k + const, k = s kk.
    s = 1.0 / math.sqrt(curv) if unit else 1e3
    force_rows = (bit << 2) | (bit << 3)
    lo_f = lo / s if lo_bit & force_rows else -free
    hi_f = hi / s if hi_bit & force_rows else free
    return s, curv * s * s, -curv * k_free * s, kmin / s, kmax / s, lo_f, hi_f
