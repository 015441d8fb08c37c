"""The UR3e's joint position servo front end, as the UR controller runs it.

The arm is position controlled, as the real UR3e: the streamed joint
command (500 Hz) is smoothed by a first-order filter (``servo_time_constant_s``,
the UR driver's servoj lookahead) and, with an integral of the tracking
error (``servo_integral_time_s``), is the desired state of Drake's implicit
PD actuators (``JointActuator.set_controller_gains``, gains
``joint_kp_Nm_per_rad``/``joint_kd_Nms_per_rad``; :func:`_set_pd_gains`).
The servo lag matters: FDCC re-reads the measured joints every tick; see
docs/decisions.md, "Joint servo".
"""

import numpy as np
from pydrake.multibody.tree import PdControllerGains

from vic_drake.errors import VicDrakeError


def joint_filter_step(q_filtered, q_command, period_s: float, time_constant_s: float):
    """One step of the servo's first-order command smoothing.

    Returns (q_filtered_next, v_desired): the filtered position moves a
    fraction ``1 - exp(-period/tau)`` of the way to the command; the desired
    velocity is the filtered position's rate over the next period.
    """
    alpha = 1.0 - np.exp(-period_s / time_constant_s)
    q_next = q_filtered + alpha * (np.asarray(q_command, float) - q_filtered)
    return q_next, (q_next - q_filtered) / period_s


def joint_servo_system_matrices(
    n: int, period_s: float, time_constant_s: float, integral_time_s: float = 0.0
):
    """The arm's position servo front end as a discrete linear system.

    Models what the UR controller does with streamed position commands:

    - a discrete first-order filter (:func:`joint_filter_step`: period
      ``period_s``, time constant ``time_constant_s``), as the servoj
      lookahead smooths the stream;
    - integral action on the tracking error (time constant
      ``integral_time_s``; 0 disables it): the desired position is the
      filtered command plus the integral of (filtered command - measured
      position), so a static load (the tissue pushing on the probe) leaves no
      steady position error -- the real arm holds its pose under 10 N to a
      fraction of a millimetre.

    Both are linear, so the station runs them as Drake's ``LinearSystem``
    (C++, no Python per tick). State ``x = [q_f, v, I]`` (3n: filtered
    command, its rate over the last period, integral term), input
    ``u = [command; measured]`` (2n), output ``y = [q_f + I; v]`` (2n, the
    desired state of the PD actuators, from the state only)::

        q_f+ = q_f + a (command - q_f),   a = 1 - exp(-period / tau)
        v+   = a (command - q_f) / period
        I+   = I + (period / T_i) (q_f - measured)

    Returns:
        (A (3n, 3n), B (3n, 2n), C (2n, 3n), D (2n, 2n)).
    """
    n = int(n)
    alpha = 1.0 - np.exp(-period_s / time_constant_s)
    k_i = period_s / integral_time_s if integral_time_s > 0 else 0.0
    eye, zero = np.eye(n), np.zeros((n, n))
    A = np.block(
        [
            [(1.0 - alpha) * eye, zero, zero],
            [-(alpha / period_s) * eye, zero, zero],
            [k_i * eye, zero, eye],
        ]
    )
    B = np.block(
        [[alpha * eye, zero], [(alpha / period_s) * eye, zero], [zero, -k_i * eye]]
    )
    C = np.block([[eye, zero, eye], [zero, eye, zero]])
    return A, B, C, np.zeros((2 * n, 2 * n))


def joint_servo_rest_state(q) -> np.ndarray:
    """State of the servo front end at rest at q (n,): ``[q, 0, 0]``."""
    q = np.asarray(q, float)
    return np.concatenate([q, np.zeros(2 * len(q))])


def _set_pd_gains(plant, joint_names, model, kp, kd):
    for name, p_gain, d_gain in zip(joint_names, kp, kd):
        joint = plant.GetJointByName(name, model)
        actuators = [
            plant.get_joint_actuator(a)
            for a in plant.GetJointActuatorIndices(model)
            if plant.get_joint_actuator(a).joint().index() == joint.index()
        ]
        if len(actuators) != 1:
            raise VicDrakeError(f"joint {name!r} needs exactly one actuator")
        actuators[0].set_controller_gains(
            PdControllerGains(p=float(p_gain), d=float(d_gain))
        )


__all__ = ["joint_filter_step", "joint_servo_rest_state", "joint_servo_system_matrices"]
