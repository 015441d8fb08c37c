"""The QP's tank rows against the tank module."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.control.stiffness_qp.cases import K_MIN, TANK, random_problems
from vic_drake.control.params import StiffnessQpParams
from vic_drake.control.stiffness_qp.problem import make_stiffness_qp_problem


@settings(max_examples=100, deadline=None)
@given(p=random_problems(), energy=st.floats(0.0, 1.5), dt=st.floats(1e-4, 0.01))
def test_problem_tank_rows_equal_the_tank_module(p, energy, dt):
    from vic_drake.control.tank import tank_qp_rows

    q = make_stiffness_qp_problem(p.e, p.e_dot, p.damping, p.force_ref, p.force_min, energy, dt,
                                  StiffnessQpParams(r_weight=list(p.r_weight)), TANK)  # fmt: skip
    a, lb_energy, lb_power = tank_qp_rows(
        energy, p.e, p.e_dot, K_MIN, p.damping, dt, TANK
    )
    assert q.tank_a == pytest.approx(a, rel=1e-15)
    assert q.tank_lb_energy == pytest.approx(lb_energy, rel=1e-12, abs=1e-12)
    assert q.tank_lb_power == pytest.approx(lb_power, rel=1e-12, abs=1e-15)
