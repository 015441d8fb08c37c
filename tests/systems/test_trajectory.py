"""The target trajectory config and the source built from it."""

import numpy as np
import pytest

from vic_drake.scenario import TrajectoryConfig
from vic_drake.systems.trajectory import TargetTrajectorySource, target_knots


def test_parametric_target_matches_the_real_scans_profile():
    config = TrajectoryConfig()  # 0.108 -> 0.085 at 1 cm/s, 20 cm along -x, lift-off.
    t, p = target_knots(config)
    np.testing.assert_allclose(t[:3], [0.0, 2.3, 22.3])
    np.testing.assert_allclose(p[:, 1], [0.036, -0.36, 0.085])
    np.testing.assert_allclose(p[:, 2], [-0.164, -0.36, 0.085])
    np.testing.assert_allclose(p[2, -1], 0.085 + 0.048)
    assert config.end_time_s == pytest.approx(22.3)


def _eval_at(system, port, t):
    context = system.CreateDefaultContext()
    context.SetTime(t)
    return port.Eval(context)


def test_target_source_outputs_position_and_velocity():
    source = TargetTrajectorySource(TrajectoryConfig())
    p = _eval_at(source, source.get_target_position_output_port(), 12.3)
    v = _eval_at(source, source.get_target_velocity_output_port(), 12.3)
    np.testing.assert_allclose(p, [0.036 - 0.01 * 10.0, -0.36, 0.085], atol=1e-12)
    np.testing.assert_allclose(v, [-0.01, 0.0, 0.0], atol=1e-12)
    v_end = _eval_at(source, source.get_target_velocity_output_port(), 100.0)
    np.testing.assert_allclose(v_end, 0.0)


def test_waypoint_target_interpolates_the_table():
    config = TrajectoryConfig(
        waypoints=[[0, 0, 0, 0.1], [2, -0.02, 0, 0.1], [3, -0.02, 0, 0.2]]
    )
    source = TargetTrajectorySource(config)
    p = _eval_at(source, source.get_target_position_output_port(), 1.0)
    np.testing.assert_allclose(p, [-0.01, 0.0, 0.1])
    assert config.start_tip_z_m == 0.1 and config.end_time_s == 3.0


def test_target_source_equals_its_trajectory_and_stops_at_the_end():
    config = TrajectoryConfig()
    source = TargetTrajectorySource(config)
    t_knots, _ = target_knots(config)
    t_end = float(t_knots[-1])
    times = [*t_knots, *(0.5 * (t_knots[:-1] + t_knots[1:])), t_end + 3.0]
    rate = source.trajectory.derivative(1)
    for t in times:
        np.testing.assert_array_equal(
            _eval_at(source, source.get_target_position_output_port(), t),
            source.trajectory.value(t).ravel(),
        )
        v = _eval_at(source, source.get_target_velocity_output_port(), t)
        if t < t_end:  # The rate of the segment that starts at or before t.
            np.testing.assert_array_equal(v, rate.value(t).ravel())
        else:  # The target has stopped: zero at the end time and after.
            np.testing.assert_array_equal(v, [0.0, 0.0, 0.0])
