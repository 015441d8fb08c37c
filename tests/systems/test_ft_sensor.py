"""The F/T sensor model: tare, lag, bias, frames."""

import numpy as np
import pytest
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.tree import BodyIndex, JointIndex

from vic_drake.errors import VicDrakeError
from vic_drake.systems.ft_sensor import ForceTorqueSensor, tared_sensor_wrench


def test_tare_zeroes_the_static_load_in_any_orientation():
    m, p_com, g = 0.12, np.array([0.0, 0.01, 0.02]), np.array([0, 0, -9.81])
    for rpy in [(0, 0, 0), (np.pi, 0, 0), (0.3, -0.7, 1.1)]:
        R_WS = RotationMatrix(RollPitchYaw(rpy)).matrix()
        f_S = -m * (R_WS.T @ g)  # what the sensor applies to hold the mass still
        tau_S = np.cross(p_com, f_S)
        out = tared_sensor_wrench(
            np.concatenate([tau_S, f_S]), R_WS, distal_mass_kg=m, p_SScm=p_com
        )
        np.testing.assert_allclose(out, 0.0, atol=1e-12)


def _sensor(**kw):
    return ForceTorqueSensor(
        weld_joint_index=JointIndex(0),
        child_body_index=BodyIndex(1),
        X_CS=RigidTransform(),
        distal_mass_kg=0.0,
        p_SScm=np.zeros(3),
        **kw,
    )


def _fix(system, context, f_S, R_WS=None):
    R_WS = R_WS or RotationMatrix()
    system.get_reaction_forces_input_port().FixValue(
        context, [SpatialForce(np.zeros(3), f_S)]
    )
    system.get_body_poses_input_port().FixValue(
        context, [RigidTransform(), RigidTransform(R_WS, [0, 0, 0])]
    )


def test_lag_delays_by_whole_samples_and_bias_adds():
    lag = 3
    system = _sensor(lag_samples=lag, bias=[0, 0, 0, 0.5, 0, 0])
    context = system.CreateDefaultContext()
    readings = []
    for k in range(8):
        _fix(system, context, np.array([0.0, 0.0, float(k + 1)]))
        state = system.EvalUniquePeriodicDiscreteUpdate(context)
        context.SetDiscreteState(state)
        readings.append(system.get_wrench_output_port().Eval(context)[3:].copy())
    fz = [r[2] for r in readings]
    # After update k (sample k+1) the output shows the sample taken lag ticks earlier.
    assert fz == [0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    assert all(r[0] == 0.5 for r in readings)


def test_force_is_rotated_into_world():
    system = _sensor()
    context = system.CreateDefaultContext()
    R_WS = RotationMatrix.MakeXRotation(np.pi)  # tool pointing down
    _fix(system, context, np.array([0.0, 0.0, 4.0]), R_WS)
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    np.testing.assert_allclose(
        system.get_force_output_port().Eval(context), [0, 0, -4.0], atol=1e-12
    )


def test_noise_scales_the_noise_input():
    system = _sensor(noise_std=[0, 0, 0, 0.1, 0.2, 0.3])
    context = system.CreateDefaultContext()
    _fix(system, context, np.zeros(3))
    system.get_noise_input_port().FixValue(context, np.ones(6))
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    np.testing.assert_allclose(
        system.get_wrench_output_port().Eval(context), [0, 0, 0, 0.1, 0.2, 0.3]
    )


def test_unconnected_noise_input_reads_noise_free():
    """A noisy sensor without a noise input reads what a noise-free one does;
    with the input it reads the same plus the scaled noise."""
    noisy = _sensor(noise_std=[0, 0, 0, 0.1, 0.2, 0.3], bias=[0, 0, 0, 0.5, 0, 0])
    plain = _sensor(bias=[0, 0, 0, 0.5, 0, 0])
    readings = []
    for system, noise in ((noisy, None), (plain, None), (noisy, np.ones(6))):
        context = system.CreateDefaultContext()
        _fix(system, context, np.array([1.0, -2.0, 3.0]))
        if noise is not None:
            system.get_noise_input_port().FixValue(context, noise)
        context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
        readings.append(system.get_wrench_output_port().Eval(context).copy())
    np.testing.assert_array_equal(readings[0], [0, 0, 0, 1.5, -2.0, 3.0])
    np.testing.assert_array_equal(readings[0], readings[1])
    np.testing.assert_allclose(readings[2], [0, 0, 0, 1.6, -1.8, 3.3])


def test_without_lag_no_sample_buffer_is_kept():
    """The state is the reading alone without a lag, plus the samples with one."""
    assert _sensor().CreateDefaultContext().num_discrete_state_groups() == 2
    context = _sensor(lag_samples=2).CreateDefaultContext()
    assert context.num_discrete_state_groups() == 3
    assert context.get_discrete_state(0).size() == 18


def test_bad_settings_are_rejected():
    with pytest.raises(VicDrakeError, match="lag_samples"):
        _sensor(lag_samples=-1)
    with pytest.raises(VicDrakeError, match="period_s"):
        _sensor(period_s=0.0)


def test_one_sample_equals_the_pure_tare_in_any_orientation():
    """The system's tare (a precomputed matrix) against tared_sensor_wrench."""
    m, p_com = 0.12, np.array([0.003, 0.01, 0.02])
    system = ForceTorqueSensor(
        weld_joint_index=JointIndex(0),
        child_body_index=BodyIndex(1),
        X_CS=RigidTransform(RotationMatrix.MakeZRotation(0.4)),
        distal_mass_kg=m,
        p_SScm=p_com,
    )
    context = system.CreateDefaultContext()
    F_S = np.array([0.01, -0.02, 0.03, 1.0, -2.0, 3.0])
    for rpy in [(0, 0, 0), (np.pi, 0, 0), (0.3, -0.7, 1.1)]:
        R_WC = RotationMatrix(RollPitchYaw(rpy))
        system.get_reaction_forces_input_port().FixValue(
            context, [SpatialForce(F_S[:3], F_S[3:])]
        )
        system.get_body_poses_input_port().FixValue(
            context, [RigidTransform(), RigidTransform(R_WC, [0, 0, 0])]
        )
        context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
        R_WS = (R_WC @ RotationMatrix.MakeZRotation(0.4)).matrix()
        expected = tared_sensor_wrench(F_S, R_WS, distal_mass_kg=m, p_SScm=p_com)
        np.testing.assert_allclose(
            system.get_wrench_output_port().Eval(context), expected, atol=1e-14
        )
        np.testing.assert_allclose(
            system.get_force_output_port().Eval(context),
            R_WS @ expected[3:],
            atol=1e-14,
        )


def test_plant_state_input_gives_the_body_poses_numbers():
    """Built with the plant, the sensor reads its body's orientation from the
    plant's state vector: the same readings as from the body poses list."""
    from tests.systems.test_body_reader import (
        contexts_fed_both_ways,
        free_and_lifted_plant,
    )

    plant, plant_context = free_and_lifted_plant()
    kw = dict(
        weld_joint_index=JointIndex(0), child_body_index=BodyIndex(1),
        X_CS=RigidTransform(RotationMatrix.MakeZRotation(0.4)), distal_mass_kg=0.12,
        p_SScm=[0.003, 0.01, 0.02], lag_samples=1, bias=[0, 0, 0, 0.1, -0.2, 0.3],
    )  # fmt: skip
    lists, state = ForceTorqueSensor(**kw), ForceTorqueSensor(plant=plant, **kw)
    c_lists, c_state = contexts_fed_both_ways(plant, plant_context, lists, state)
    for k in range(3):
        reaction = [SpatialForce([0.01 * k, -0.02, 0.03], [1.0, -2.0 * k, 3.0])]
        for system, context in ((state, c_state), (lists, c_lists)):
            system.get_reaction_forces_input_port().FixValue(context, reaction)
            context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
        np.testing.assert_array_equal(state.tared_wrench(c_state),
                                      lists.tared_wrench(c_lists))  # fmt: skip
        for port in ("wrench_S", "force_W"):
            np.testing.assert_array_equal(
                state.GetOutputPort(port).Eval(c_state),
                lists.GetOutputPort(port).Eval(c_lists),
            )
    assert np.any(state.get_force_output_port().Eval(c_state) != 0)
