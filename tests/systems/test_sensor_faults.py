"""FaultySensor and PatientMotionSource: thin systems over the pure models."""

import numpy as np
import pytest

from vic_drake.scenario import DisturbanceConfig, PhantomLift
from vic_drake.systems.patient_motion import PatientMotionSource
from vic_drake.systems.sensor_faults import FaultySensor
from vic_drake.tissue.motion import breath_cycles, breathing_offset_m


def _step(sensor, context, t, u):
    context.SetTime(t)
    sensor.get_input_port_force().FixValue(context, u)
    y = sensor.get_output_port_force().Eval(context).copy()
    context.SetDiscreteState(sensor.EvalUniquePeriodicDiscreteUpdate(context))
    return y


def test_latency_delays_the_reading_by_whole_ticks():
    sensor = FaultySensor(period_s=0.002, duration_s=1.0, seed=0, extra_latency_s=0.006)
    context = sensor.CreateDefaultContext()
    out = [_step(sensor, context, 0.002 * k, [k, 0, -k])[0] for k in range(8)]
    np.testing.assert_allclose(out, [0, 0, 0, 0, 1, 2, 3, 4])


def test_stuck_channel_keeps_its_value_from_the_start_time():
    sensor = FaultySensor(
        period_s=0.002, duration_s=1.0, seed=0, stuck_channel=1, stuck_start_s=0.004
    )
    context = sensor.CreateDefaultContext()
    out = np.array([_step(sensor, context, 0.002 * k, [k, k, k]) for k in range(6)])
    np.testing.assert_allclose(out[:, 1], [0, 1, 2, 2, 2, 2])
    np.testing.assert_allclose(out[:, 0], range(6))


def test_patient_motion_sums_lifts_and_breathing():
    lifts = DisturbanceConfig(lifts=[PhantomLift(start_s=1.0)])
    cycles = breath_cycles(
        frequency_hz=0.25, amplitude_m=0.01, irregularity=0.0, duration_s=10, seed=0
    )
    source = PatientMotionSource(lifts, breaths=cycles)
    context = source.CreateDefaultContext()
    context.SetTime(2.5)  # Lift at full height (0.02 m) plus breathing.
    z = source.get_phantom_lift_output_port().Eval(context)[0]
    assert z == pytest.approx(0.02 + breathing_offset_m(2.5, cycles))
