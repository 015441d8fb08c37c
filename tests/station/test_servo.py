"""The joint servo front end: the LinearSystem against the filter and integral."""

import numpy as np
from pydrake.systems.primitives import LinearSystem

from vic_drake.station import (
    joint_filter_step,
    joint_servo_rest_state,
    joint_servo_system_matrices,
)


def test_servo_linear_system_steps_as_the_filter_and_integral():
    """One tick of the servo's LinearSystem against joint_filter_step and the
    integral written out (period 2 ms, tau 0.03 s, T_i 0.05 s)."""
    T, tau, ti = 0.002, 0.03, 0.05
    servo = LinearSystem(*joint_servo_system_matrices(6, T, tau, ti), T)
    context = servo.CreateDefaultContext()
    rng = np.random.default_rng(0)
    q_f, v, integral = rng.normal(size=(3, 6))
    context.SetDiscreteState(np.concatenate([q_f, v, integral]))
    command, measured = rng.normal(size=(2, 6))
    servo.get_input_port().FixValue(context, np.concatenate([command, measured]))
    x = servo.EvalUniquePeriodicDiscreteUpdate(context).get_vector().CopyToVector()
    q_next, v_next = joint_filter_step(q_f, command, T, tau)
    i_next = integral + (T / ti) * (q_f - measured)
    np.testing.assert_allclose(x, np.concatenate([q_next, v_next, i_next]), atol=1e-12)
    context.SetDiscreteState(x)
    np.testing.assert_allclose(
        servo.get_output_port().Eval(context),
        np.concatenate([q_next + i_next, v_next]),
        atol=1e-12,
    )
    # No integral term with T_i = 0; at rest the output is (q, 0).
    A, B, _, _ = joint_servo_system_matrices(6, T, tau, 0.0)
    assert not A[12:, :12].any() and not B[12:].any()
    rest = joint_servo_rest_state(q_f)
    np.testing.assert_array_equal(rest, np.concatenate([q_f, np.zeros(12)]))
