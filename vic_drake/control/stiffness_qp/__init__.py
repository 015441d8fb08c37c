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

One concept per module:

- :mod:`~vic_drake.control.stiffness_qp.problem`: the tick's numbers
  (:class:`StiffnessQpProblem`, :func:`make_stiffness_qp_problem`), the
  answer (:class:`StiffnessQpSolution`), cost and violation checks.
- :mod:`~vic_drake.control.stiffness_qp.constraints`: the active-constraint
  bit mask.
- :mod:`~vic_drake.control.stiffness_qp.exact`:
  :func:`solve_stiffness_qp_exact`, closed form on the KKT conditions (test
  oracle and fast path).
- :mod:`~vic_drake.control.stiffness_qp.program`: :class:`StiffnessQp`, a
  Drake ``MathematicalProgram`` built once, solved by OSQP or Clarabel.

A failed or infeasible solve returns K_min with ``success=False``; callers
count these (the LeafSystem keeps the count in its state).
"""

from vic_drake.control.stiffness_qp.constraints import (
    ACTIVE_TANK_ENERGY,
    ACTIVE_TANK_POWER,
    AXES,
    active_bit,
    active_constraint_names,
    active_constraints,
)
from vic_drake.control.stiffness_qp.exact import solve_stiffness_qp_exact
from vic_drake.control.stiffness_qp.problem import (
    StiffnessQpProblem,
    StiffnessQpSolution,
    make_stiffness_qp_problem,
    stiffness_qp_cost,
    stiffness_qp_violation,
)
from vic_drake.control.stiffness_qp.program import StiffnessQp

__all__ = [
    "ACTIVE_TANK_ENERGY",
    "ACTIVE_TANK_POWER",
    "AXES",
    "StiffnessQp",
    "StiffnessQpProblem",
    "StiffnessQpSolution",
    "active_bit",
    "active_constraint_names",
    "active_constraints",
    "make_stiffness_qp_problem",
    "solve_stiffness_qp_exact",
    "stiffness_qp_cost",
    "stiffness_qp_violation",
]
