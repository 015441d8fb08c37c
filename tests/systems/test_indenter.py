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
