"""Problems shared by the stiffness QP tests: defaults and a random-problem strategy."""

import math

from hypothesis import strategies as st

from vic_drake.control.params import StiffnessQpParams, TankParams
from vic_drake.control.stiffness_qp.problem import make_stiffness_qp_problem

QP = StiffnessQpParams()
TANK = TankParams()
K_MIN = tuple(QP.stiffness_min_N_per_m)
ZERO = (0.0, 0.0, 0.0)


def problem(e, e_dot=ZERO, damping=(24.5, 24.5, 14.1), f_ref=(0, 0, -7.0), f_min=(-15, -15, -15),
            energy=0.6, dt=0.002, qp=QP, tank=TANK):  # fmt: skip
    return make_stiffness_qp_problem(
        e, e_dot, damping, f_ref, f_min, energy, dt, qp, tank
    )


vec = lambda s: st.tuples(*[st.floats(-s, s)] * 3)  # noqa: E731


@st.composite
def random_problems(draw):
    r = draw(st.sampled_from([1e-5, 1e-3, 0.1, 10.0]))
    qp = StiffnessQpParams(r_weight=[r] * 3)
    k_prev = draw(
        st.tuples(st.floats(300, 1000), st.floats(300, 1000), st.floats(100, 1000))
    )
    damping = tuple(2 * 0.707 * math.sqrt(k) for k in k_prev)
    f_ref = (0.0, 0.0, -draw(st.floats(0.0, 14.0)))
    f_min = (-15.0, -15.0, -draw(st.floats(1.0, 15.0)))
    return make_stiffness_qp_problem(
        draw(vec(0.03)), draw(vec(0.05)), damping, f_ref, f_min,
        draw(st.floats(0.4, 1.2)), draw(st.floats(5e-4, 4e-3)), qp, TANK,
    )  # fmt: skip


def tank_row_resolvable(p, tol_W: float = 1e-6) -> bool:
    """Whether the tank row can change a'K by tol_W or more over the
    stiffness box (or is absent). Rows below that (e e_dot near underflow,
    e.g. a = -1.7e-310 with a bound of -1.7e-308, i.e. K_z <= 100) are honoured
    exactly by the exact solver and are below any iterative solver's
    tolerance, so the two may differ in K while both are feasible to
    tol_W."""
    span = sum(
        abs(a) * (hi - lo)
        for a, lo, hi in zip(p.tank_a, p.stiffness_min, p.stiffness_max)
    )
    return span == 0.0 or span >= tol_W
