"""The FDCC step: error conventions, free-space convergence, force tracking, faults."""

import numpy as np
import pytest
from pydrake.math import RotationMatrix
from scipy.linalg.lapack import dgesv

from vic_drake.control.fdcc import (
    FdccConstants,
    FdccParams,
    fdcc_step,
    fdcc_tick,
    net_cartesian_error,
)
from vic_drake.errors import VicDrakeError
from vic_drake.models.ur3e import MakeFdccModel, probe_down_rotation
from vic_drake.station import StationParams, initial_q_for_tip, joint_filter_step

START = np.array([-0.06, -0.36, 0.13])


@pytest.fixture(scope="module")
def model():
    return MakeFdccModel(FdccParams(), StationParams())


@pytest.fixture(scope="module")
def q_start():
    return initial_q_for_tip(START)


def _run(
    model, params, q0, *, ticks, target, stiffness, force_fn, lag=0, servo_tau=None
):
    """Closed loop with a kinematic arm.

    The arm is where commanded (``servo_tau`` None) or follows the command
    through the station's first-order servo smoothing. force_fn(p_WP) gives
    the measured force (sensor convention); ``lag`` delays it by whole ticks.
    """
    q, qd, err = q0.copy(), np.zeros(6), np.zeros(6)
    q_arm = q0.copy()
    forces = [np.zeros(3)] * (lag + 1)
    for _ in range(ticks):
        forces.append(force_fn(model.pose(q_arm).translation()))
        step = fdcc_step(
            model,
            params,
            q_measured=q_arm,
            q_command_prev=q,
            qdot=qd,
            last_error=err,
            p_WP_target=target,
            stiffness=stiffness,
            measured_force=forces[-1 - lag],
            target_force=force_fn.target,
        )
        assert step.ok
        q, qd, err = step.q_command, step.qdot, step.last_error
        if servo_tau is None:
            q_arm = q
        else:
            q_arm, _ = joint_filter_step(q_arm, q, params.period_s, servo_tau)
    return q_arm


def test_net_error_signs(model, q_start):
    X = model.pose(q_start)
    R = probe_down_rotation()
    up = net_cartesian_error(
        X,
        X.translation() + [0, 0, 0.01],
        R,
        [100, 100, 100],
        [50] * 3,
        np.zeros(3),
        np.zeros(3),
    )
    np.testing.assert_allclose(up[:3], [0, 0, 1.0], atol=1e-6)
    # Pressing harder (sensor -9 N) than the target (-7 N): the net force lifts.
    press = net_cartesian_error(
        X, X.translation(), R, [0, 0, 0], [50] * 3, [0, 0, -9.0], [0, 0, -7.0]
    )
    np.testing.assert_allclose(press[:3], [0, 0, 2.0], atol=1e-6)
    # A target turned about +x of W gives a positive torque about x.
    R_turned = RotationMatrix.MakeXRotation(0.01) @ X.rotation()
    rot = net_cartesian_error(
        X, X.translation(), R_turned, [0] * 3, [50] * 3, np.zeros(3), np.zeros(3)
    )
    np.testing.assert_allclose(rot[3:], [0.5, 0, 0], atol=1e-6)


def test_free_space_step_converges_with_tool_down(model, q_start):
    params = FdccParams()
    target = START + [0.02, -0.01, 0.015]

    def no_force(p):
        return np.zeros(3)

    no_force.target = np.zeros(3)
    q = _run(
        model,
        params,
        q_start,
        ticks=3000,
        target=target,
        stiffness=[400] * 3,
        force_fn=no_force,
    )
    X = model.pose(q)
    np.testing.assert_allclose(X.translation(), target, atol=2e-4)
    np.testing.assert_allclose(
        X.rotation().matrix(), probe_down_rotation().matrix(), atol=1e-3
    )


@pytest.mark.parametrize(
    "k_spring, lag, servo_tau", [(2000.0, 0, None), (800.0, 28, 0.03)]
)
def test_zero_stiffness_force_target_settles_on_a_spring(
    model, q_start, k_spring, lag, servo_tau
):
    """A linear spring 5 mm below the start; the target is 7 N pressing.

    With the sensor's 28-sample lag the loop needs the arm's servo lag (the
    rig's servoj smoothing) and a contact stiffness like soft tissue's
    (Hunt-Crossley at 7 N on kappa 2700: about 800 N/m); on 2000 N/m it
    settles into a limit cycle (the FZI gains' force loop is that fast).
    """
    params = FdccParams()
    surface = START[2] - 0.005

    def spring(p):
        push_up = k_spring * max(surface - p[2], 0.0)
        return np.array([0.0, 0.0, -push_up])  # sensor convention

    spring.target = np.array([0.0, 0.0, -7.0])
    q = _run(
        model,
        params,
        q_start,
        ticks=4000,
        target=START,
        stiffness=[300, 300, 0],
        force_fn=spring,
        lag=lag,
        servo_tau=servo_tau,
    )
    p = model.pose(q).translation()
    assert spring(p)[2] == pytest.approx(-7.0, abs=0.05)
    np.testing.assert_allclose(p[:2], START[:2], atol=1e-3)


def test_nan_input_holds_the_last_command(model, q_start):
    params = FdccParams()
    q_prev = q_start + 0.01
    step = fdcc_step(
        model,
        params,
        q_measured=q_start,
        q_command_prev=q_prev,
        qdot=np.ones(6),
        last_error=np.zeros(6),
        p_WP_target=START,
        stiffness=[300, 300, np.nan],
        measured_force=np.zeros(3),
        target_force=np.zeros(3),
    )
    assert not step.ok
    np.testing.assert_array_equal(step.q_command, q_prev)
    np.testing.assert_array_equal(step.qdot, np.zeros(6))


def test_joint_limits_clamp(model, q_start):
    params = FdccParams()
    q = q_start.copy()
    q[2] = model.q_upper[2] - 1e-4  # elbow at its +pi limit
    step = fdcc_step(
        model,
        params,
        q_measured=q,
        q_command_prev=q,
        qdot=np.full(6, 10.0),
        last_error=np.zeros(6),
        p_WP_target=START,
        stiffness=[300] * 3,
        measured_force=np.zeros(3),
        target_force=np.zeros(3),
    )
    assert step.ok and step.q_command[2] <= model.q_upper[2]
    assert step.qdot[2] == 0.0


@pytest.mark.parametrize(
    "field, value",
    [
        ("error_scale", 0.0),
        ("iterations", 0),
        ("p_gains", (1.0,) * 5),
        ("velocity_decay", 1.5),
        ("d_gains", (-1.0,) * 6),
        ("pose_feedback", "target"),
    ],
)
def test_bad_params_name_the_field(field, value):
    with pytest.raises(VicDrakeError, match=field):
        FdccParams(**{field: value})


def test_compliance_equilibrium_against_a_spring(model, q_start):
    """CS use: K = 400 N/m, target 1.5 cm into a 1500 N/m spring, no force
    target: the probe settles where the spring force equals K (z - z_d)."""
    params = FdccParams()
    surface, k_spring, K = START[2] - 0.005, 1500.0, 400.0

    def spring(p):
        return np.array([0.0, 0.0, -k_spring * max(surface - p[2], 0.0)])

    spring.target = np.zeros(3)
    target = np.array([START[0], START[1], surface - 0.015])
    q = _run(
        model,
        params,
        q_start,
        ticks=4000,
        target=target,
        stiffness=[K] * 3,
        force_fn=spring,
        lag=28,
        servo_tau=0.03,
    )
    z = model.pose(q).translation()[2]
    # Closed form: k_s (s - z) = K (z - z_d).
    z_eq = (k_spring * surface + K * target[2]) / (k_spring + K)
    assert z == pytest.approx(z_eq, abs=5e-5)


def _numpy_oracle(model, params, q, q_prev, qd, err_prev, x_d, K, f_m, f_t):
    """The FDCC tick written with numpy arrays, as the module docstring states it."""
    R_d = params.R_WP_target
    dt = params.internal_period_s
    p, d = np.asarray(params.p_gains), np.asarray(params.d_gains)
    K_rot = np.asarray(params.rotational_stiffness_Nm_per_rad)
    for i in range(params.iterations):
        X, H, J = model.dynamics(q)
        if i == 0 and params.pose_feedback == "command":
            X = model.pose(q_prev)
        aa = (R_d @ X.rotation().inverse()).ToAngleAxis()
        err = np.concatenate(
            [
                K * (x_d - X.translation()) + (f_t - f_m),
                K_rot * (aa.axis() * aa.angle()),
            ]
        )
        u = params.error_scale * (p * err + d * (err - err_prev) / dt)
        err_prev = err
        _, _, qdd, info = dgesv(H, J.T @ np.concatenate([u[3:], u[:3]]))
        assert info == 0
        q_next = q + qd * dt
        qd = params.velocity_decay * (qd + qdd * dt)
        below, above = q_next < model.q_lower, q_next > model.q_upper
        q = np.minimum(np.maximum(q_next, model.q_lower), model.q_upper)
        qd[(below & (qd < 0)) | (above & (qd > 0))] = 0.0
    return q, qd, err_prev


@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"iterations": 3, "pose_feedback": "command"},
        {
            "iterations": 2,
            "p_gains": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
            "d_gains": [0.01, 0.0, 0.02, 0.003, 0.0, 0.001],
            "error_scale": 0.7,
            "velocity_decay": 0.8,
            "internal_period_s": 0.013,
            "target_orientation_wxyz": [0.1, 0.9, -0.2, 0.05],
        },
    ],
)
def test_tick_equals_the_numpy_formulation_exactly(kw, q_start):
    """fdcc_step / fdcc_tick (plain floats) give the numpy formulation's bits,
    also where a joint is clamped at its limit."""
    params = FdccParams(**kw)
    model = MakeFdccModel(params, StationParams())
    constants = FdccConstants.from_params(params)
    rng = np.random.default_rng(3)
    for k in range(40):
        q = q_start + rng.normal(0, 0.3, 6)
        qd = rng.normal(0, 2.0, 6)
        if k % 4 == 0:  # at the elbow's upper limit, moving into it
            q[2], qd[2] = model.q_upper[2] - 1e-5, 5.0
        args = (
            q,
            q + rng.normal(0, 0.01, 6),
            qd,
            rng.normal(0, 5, 6),
            START + rng.normal(0, 0.02, 3),
            rng.uniform(0, 2000, 3),
            rng.normal(0, 10, 3),
            rng.normal(0, 10, 3),
        )
        want = _numpy_oracle(model, params, *args)
        step = fdcc_step(
            model,
            params,
            **dict(
                zip(
                    (
                        "q_measured",
                        "q_command_prev",
                        "qdot",
                        "last_error",
                        "p_WP_target",
                        "stiffness",
                        "measured_force",
                        "target_force",
                    ),
                    args,
                )
            ),
        )
        assert step.ok
        for got, expected in zip((step.q_command, step.qdot, step.last_error), want):
            np.testing.assert_array_equal(got, expected)
        tick = fdcc_tick(model, constants, *args)
        for got, expected in zip(tick, want):
            np.testing.assert_array_equal(got, expected)


def test_tick_faults(model, q_start):
    constants = FdccConstants.from_params(FdccParams())
    z3, z6 = np.zeros(3), np.zeros(6)
    args = [q_start, q_start, z6, z6, START, np.full(3, 300.0), z3, z3]
    assert fdcc_tick(model, constants, *args) is not None
    for index, bad in [
        (5, np.array([300.0, -1.0, 300.0])),
        (6, np.array([0, np.inf, 0])),
    ]:
        faulty = list(args)
        faulty[index] = bad
        assert fdcc_tick(model, constants, *faulty) is None


def test_wrong_length_argument_is_named(model, q_start):
    with pytest.raises(VicDrakeError, match="stiffness"):
        fdcc_step(
            model,
            FdccParams(),
            q_measured=q_start,
            q_command_prev=q_start,
            qdot=np.zeros(6),
            last_error=np.zeros(6),
            p_WP_target=START,
            stiffness=300.0,
            measured_force=np.zeros(3),
            target_force=np.zeros(3),
        )
