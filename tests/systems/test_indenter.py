"""The indenter's systems: Hunt-Crossley tissue, lagged F/T sensor, palpation target."""

import numpy as np
import pytest

from vic_drake.systems.indenter import (
    HuntCrossleyIndentation,
    LaggedForceSensor,
    PalpationParams,
    SensorParams,
    palpation_target,
)
from vic_drake.tissue import hunt_crossley_force

BETA = 1.35


def test_hunt_crossley_system_calls_the_force_law():
    system = HuntCrossleyIndentation(3, BETA)
    context = system.CreateDefaultContext()
    s = np.array([0.10, 0.10, 0.10])
    kappa, lam = np.array([2000.0, 5000.0, 9000.0]), np.array([2e4, 6e4, 2e5])
    system.set_tissue(context, surface_z=s, kappa=kappa, lam=lam)
    q = np.array([0.095, 0.101, 0.09])  # in contact, out of contact, pulling away fast
    v = np.array([-0.01, 0.0, 0.5])
    system.get_indenter_state_input_port().FixValue(context, np.concatenate([q, v]))
    force = system.get_generalized_force_output_port().Eval(context)
    expected = hunt_crossley_force(s - q, -v, kappa, lam, BETA, clip_tension=True)
    np.testing.assert_allclose(force, expected, rtol=1e-12)
    assert force[1] == 0.0 and force[2] == 0.0  # no contact; no tension
    assert force[0] > 0.0


def test_lagged_sensor_delays_by_lag_samples():
    params = SensorParams(lag_samples=3, noise_std_N=0.0)
    sensor = LaggedForceSensor(2, params, indenter_mass_kg=0.1)
    context = sensor.CreateDefaultContext()
    sensor.GetInputPort("tissue_force").FixValue(context, [5.0, 1.0])
    sensor.GetInputPort("acceleration").FixValue(context, [2.0, 0.0])
    sensor.GetInputPort("noise").FixValue(context, [0.0, 0.0])
    outputs = []
    for _ in range(5):
        outputs.append(sensor.get_measured_force_output_port().Eval(context).copy())
        update = sensor.EvalUniquePeriodicDiscreteUpdate(context)
        context.SetDiscreteState(update.get_vector().get_value())
    # Reading F - m_I a = 5 - 0.2 = 4.8 appears after lag + 1 updates.
    np.testing.assert_allclose(outputs[3], [0.0, 0.0])
    np.testing.assert_allclose(outputs[4], [4.8, 1.0])


def test_palpation_target_switches_to_the_sinusoid():
    p = PalpationParams(velocity_feedforward=True)
    mode = np.array([0.0, 1.0])
    z_d, v_d = palpation_target(
        1.0, mode, np.array([0.2, 0.2]), np.array([0.1, 0.1]), np.array([0.0, 0.9]), p
    )
    assert z_d[0] == pytest.approx(0.2 - p.approach_speed_m_per_s)
    w = 2 * np.pi * p.frequency_hz
    assert z_d[1] == pytest.approx(0.1 - p.depth_m - p.amplitude_m * np.sin(w * 0.1))
    assert v_d[1] == pytest.approx(-p.amplitude_m * w * np.cos(w * 0.1))
    z_d, v_d = palpation_target(
        1.0,
        mode,
        np.array([0.2, 0.2]),
        np.array([0.1, 0.1]),
        np.array([0.0, 0.9]),
        PalpationParams(),
    )
    np.testing.assert_array_equal(v_d, 0.0)  # no feed-forward by default


def test_relaxing_indentation_ticks_the_exact_update():
    """One tick moves the branch state by relaxation_step; the force follows it."""
    from vic_drake.tissue import (
        DEFAULT_RELAXATION,
        relaxation_input,
        relaxation_step,
        relaxing_hunt_crossley_force,
    )

    system = HuntCrossleyIndentation(2, BETA, update_period_s=0.002)
    assert system.n_branches == DEFAULT_RELAXATION.n_branches
    context = system.CreateDefaultContext()
    s, kappa, lam = (
        np.array([0.1, 0.1]),
        np.array([3000.0, 6000.0]),
        np.array([2e4, 5e4]),
    )
    system.set_tissue(context, surface_z=s, kappa=kappa, lam=lam)
    q, v = np.array([0.09, 0.095]), np.array([-0.01, 0.0])
    system.get_indenter_state_input_port().FixValue(context, np.concatenate([q, v]))
    fresh = system.get_generalized_force_output_port().Eval(context)
    np.testing.assert_allclose(
        fresh, hunt_crossley_force(s - q, -v, kappa, lam, BETA), rtol=1e-12
    )
    state = np.zeros((2, DEFAULT_RELAXATION.n_branches))
    for _ in range(50):
        update = system.EvalUniquePeriodicDiscreteUpdate(context)
        context.SetDiscreteState(update.get_vector().get_value())
        state = relaxation_step(
            state,
            relaxation_input(s - q, BETA),
            0.002,
            DEFAULT_RELAXATION.time_constants_s,
        )
    np.testing.assert_allclose(
        context.get_discrete_state_vector().get_value(), state.ravel(), rtol=1e-12
    )
    expected = relaxing_hunt_crossley_force(
        s - q, -v, kappa, lam, BETA, state, DEFAULT_RELAXATION.fractions
    )
    force = system.get_generalized_force_output_port().Eval(context)
    np.testing.assert_allclose(force, expected, rtol=1e-12)
    assert np.all(force < fresh)  # The tissue has relaxed.
    # Switched to plain HC in the context, the state no longer matters.
    system.set_relaxation(context, None)
    np.testing.assert_allclose(
        system.get_generalized_force_output_port().Eval(context), fresh, rtol=1e-12
    )


def test_indentation_relaxation_is_checked_and_optional():
    from vic_drake.errors import VicDrakeError
    from vic_drake.tissue import RelaxationParams

    system = HuntCrossleyIndentation(1, BETA)
    with pytest.raises(VicDrakeError, match="branches"):
        system.set_relaxation(
            system.CreateDefaultContext(),
            RelaxationParams(fractions=(0.1, 0.1), time_constants_s=(1.0, 9.0)),
        )
    plain = HuntCrossleyIndentation(1, BETA, relaxation=None)
    assert plain.n_branches == 0
    assert plain.CreateDefaultContext().num_discrete_state_groups() == 0
