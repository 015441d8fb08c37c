"""The relaxing Hunt-Crossley law: step response, equilibrium, discrete update."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.tissue import (
    DEFAULT_RELAXATION,
    RelaxationParams,
    hunt_crossley_force,
    relaxation_history,
    relaxation_input,
    relaxation_step,
    relaxing_hunt_crossley_force,
    tissue_relaxation,
)

BETA = 1.35
KAPPA, LAM = 3000.0, 2e4
TWO = RelaxationParams(fractions=(0.1, 0.2), time_constants_s=(0.5, 8.0))


def test_step_response_is_the_prony_series():
    """A held penetration: F(t) = kappa u G(t) at every tick (exact update)."""
    dt, eps = 0.002, 0.01
    u = relaxation_input(eps, BETA)
    state = np.zeros(2)
    for k in range(1, 3001):
        state = relaxation_step(state, u, dt, TWO.time_constants_s)
        force = relaxing_hunt_crossley_force(
            eps, 0.0, KAPPA, LAM, BETA, state, TWO.fractions
        )
        if k % 500 == 0:
            expected = KAPPA * u * TWO.relaxation_function(k * dt)
            assert float(force) == pytest.approx(float(expected), rel=1e-12)
    # At t = 0+ the instantaneous modulus, at t >> tau the relaxed one.
    assert TWO.relaxation_function(0.0) == pytest.approx(1.0)
    assert TWO.relaxation_function(1e4) == pytest.approx(TWO.long_term_fraction)


def test_slow_press_is_plain_hc_with_the_relaxed_kappa():
    """Equilibrium (s_i = u, eps_dot = 0) is HC with kappa g_inf."""
    eps = np.array([0.002, 0.008, 0.015])
    u = relaxation_input(eps, BETA)
    state = np.repeat(u[:, None], 2, axis=1)
    force = relaxing_hunt_crossley_force(
        eps, 0.0, KAPPA, LAM, BETA, state, TWO.fractions
    )
    expected = hunt_crossley_force(eps, 0.0, KAPPA * TWO.long_term_fraction, LAM, BETA)
    np.testing.assert_allclose(force, expected, rtol=1e-12)


def test_without_relaxation_it_is_hunt_crossley():
    eps = np.array([-0.001, 0.004, 0.01])
    eps_dot = np.array([0.0, 0.02, -0.05])
    state = np.full((3, 2), 1e-3)  # Any state: g = 0 ignores it.
    force = relaxing_hunt_crossley_force(
        eps, eps_dot, KAPPA, LAM, BETA, state, (0.0, 0.0), clip_tension=True
    )
    expected = hunt_crossley_force(eps, eps_dot, KAPPA, LAM, BETA, clip_tension=True)
    np.testing.assert_allclose(force, expected, rtol=1e-12)
    assert force[0] == 0.0


def test_unloading_after_a_hold_recovers_out_of_contact():
    """After a hold the states are loaded; out of contact they decay to zero."""
    state = np.array([relaxation_input(0.01, BETA)] * 2)
    force = relaxing_hunt_crossley_force(
        0.002, 0.0, KAPPA, LAM, BETA, state, TWO.fractions, clip_tension=True
    )
    assert float(force) == 0.0  # The relaxed part exceeds the shallow elastic one.
    state = relaxation_step(state, relaxation_input(-0.001, BETA), 1000.0, (0.5, 8.0))
    np.testing.assert_allclose(state, 0.0, atol=1e-12)


def test_history_runs_the_step_along_uneven_samples():
    rng = np.random.default_rng(0)
    t = np.cumsum(rng.uniform(0.001, 0.003, 400))
    u = relaxation_input(0.01 * np.sin(3 * t), BETA)
    hist = relaxation_history(t, u, TWO.time_constants_s)
    state = np.zeros(2)
    for k in range(1, t.size):
        state = relaxation_step(state, u[k - 1], t[k] - t[k - 1], TWO.time_constants_s)
        np.testing.assert_allclose(hist[k], state, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(hist[0], 0.0)


def test_state_broadcasts_over_probes():
    u = np.array([1e-3, 2e-3, 0.0])
    state = relaxation_step(np.zeros((3, 2)), u, 0.1, TWO.time_constants_s)
    assert state.shape == (3, 2)
    np.testing.assert_allclose(state[:, 0], u * (1 - np.exp(-0.1 / 0.5)), rtol=1e-12)


@pytest.mark.parametrize(
    "fractions, taus, word",
    [
        ((0.6, 0.5), (1.0, 2.0), "sum to < 1"),
        ((-0.1,), (1.0,), ">= 0"),
        ((0.1,), (0.0,), "> 0"),
        ((0.1, 0.1), (1.0,), "same length"),
    ],
)
def test_bad_relaxation_params_are_named(fractions, taus, word):
    with pytest.raises(VicDrakeError, match=word):
        RelaxationParams(fractions=fractions, time_constants_s=taus)


def test_tissue_laws():
    assert tissue_relaxation("relaxing") is DEFAULT_RELAXATION
    assert tissue_relaxation("hc") is None
    with pytest.raises(VicDrakeError, match="relaxing"):
        tissue_relaxation("maxwell")
    assert 0.0 < DEFAULT_RELAXATION.long_term_fraction < 1.0
