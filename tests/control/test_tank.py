"""Energy tank: closed-form ticks, sigma, T_min floor, the QP's tank rows."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vic_drake.control.params import TankParams
from vic_drake.control.tank import (
    tank_enabled,
    tank_energy,
    tank_qp_rows,
    tank_sigma,
    tank_state,
    tank_step,
)

K_MIN = (300.0, 300.0, 100.0)
TANK = TankParams()


def test_state_energy_round_trip():
    assert tank_energy(1.0) == 0.5
    assert tank_state(0.5) == pytest.approx(1.0)
    assert tank_energy(tank_state(0.73)) == pytest.approx(0.73, rel=1e-15)


def test_sigma_and_enabled_thresholds():
    assert tank_sigma(0.999, TANK) == 1.0 and tank_sigma(1.0, TANK) == 0.0
    assert tank_enabled(0.4, TANK) and not tank_enabled(0.3999, TANK)


def test_one_tick_closed_form():
    e, e_dot = (0.0, 0.0, -0.01), (0.0, 0.0, 0.02)
    k, d, dt = (300.0, 300.0, 500.0), (24.5, 24.5, 28.0), 0.002
    step = tank_step(0.6, e, e_dot, k, K_MIN, d, dt, TANK)
    p_stiff = -0.01 * 0.02 * (500.0 - 100.0)  # -0.08 W, drains.
    p_damp = 28.0 * 0.02**2  # sigma = 1 below T_max.
    assert step.power_W == pytest.approx(p_stiff + p_damp, rel=1e-14)
    assert step.energy_J == pytest.approx(0.6 + (p_stiff + p_damp) * dt, rel=1e-14)
    assert step.sigma == 1.0 and step.enabled
    full = tank_step(1.2, e, e_dot, k, K_MIN, d, dt, TANK)  # sigma = 0: no storage.
    assert full.power_W == pytest.approx(p_stiff, rel=1e-14) and full.sigma == 0.0


def test_below_t_min_uses_k_min_and_floor():
    e, e_dot, d = (0.0, 0.0, -0.01), (0.0, 0.0, 0.02), (0.0, 0.0, 28.0)
    step = tank_step(0.3, e, e_dot, (300.0, 300.0, 900.0), K_MIN, d, 0.002, TANK)
    assert not step.enabled
    assert step.power_W == pytest.approx(28.0 * 0.02**2)  # Stiffness term ignored.
    assert step.energy_J == pytest.approx(
        0.4 + 28.0 * 0.02**2 * 0.002
    )  # Floored at T_min.
    no_floor = TankParams(floor_at_min=False)
    step = tank_step(0.3, e, e_dot, (300.0, 300.0, 900.0), K_MIN, d, 0.002, no_floor)
    assert step.energy_J == pytest.approx(0.3 + 28.0 * 0.02**2 * 0.002)


vec = st.tuples(*[st.floats(-0.05, 0.05)] * 3)
kvec = st.tuples(st.floats(300, 1000), st.floats(300, 1000), st.floats(100, 1000))


@settings(max_examples=200, deadline=None)
@given(e=vec, k=kvec, energy=st.floats(0.0, 2.0), dt=st.floats(1e-4, 0.01))
def test_zero_motion_leaves_tank_unchanged(e, k, energy, dt):
    d = tuple(2 * 0.707 * math.sqrt(v) for v in k)
    step = tank_step(
        energy, e, (0.0, 0.0, 0.0), k, K_MIN, d, dt, TankParams(floor_at_min=False)
    )
    assert step.energy_J == energy and step.power_W == 0.0


@settings(max_examples=300, deadline=None)
@given(e=vec, e_dot=vec, k=kvec, energy=st.floats(0.4, 1.5), dt=st.floats(1e-4, 0.01))
def test_tank_rows_are_the_energy_and_power_conditions(e, e_dot, k, energy, dt):
    d = tuple(2 * 0.707 * math.sqrt(v) for v in K_MIN)
    a, lb_energy, lb_power = tank_qp_rows(energy, e, e_dot, K_MIN, d, dt, TANK)
    ak = sum(ai * ki for ai, ki in zip(a, k))
    step = tank_step(energy, e, e_dot, k, K_MIN, d, dt, TANK)
    scale = 1e-9 * (1.0 + sum(abs(ai) * 1000 for ai in a) + abs(lb_energy))
    # a'k >= lb_energy  <=>  T+ >= T_min ;  a'k >= lb_power  <=>  power >= eta.
    assert (ak - lb_energy) * dt == pytest.approx(
        step.energy_J - TANK.min_energy_J, abs=scale
    )
    assert ak - lb_power == pytest.approx(step.power_W - TANK.power_limit_W, abs=scale)
