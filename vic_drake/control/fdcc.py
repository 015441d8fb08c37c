"""Forward dynamics compliance control (FDCC), the real rig's Cartesian layer.

Scherzinger et al. 2017 ("Forward Dynamics Compliance Control (FDCC): A new
approach to cartesian compliance for robotic manipulators"), as implemented
in FZI's ``cartesian_controllers`` (``CartesianComplianceController`` with
the ``ForwardDynamicsSolver``) and run on the paper's UR3e. Each controller
tick (500 Hz):

1. the internal model -- the UR3e's kinematics with tiny link masses
   (``link_mass_kg`` at each moving link's origin, inertia
   ``link_inertia_kg_m2``) and a unit mass and inertia at the end effector
   (the ``probe`` frame), as FZI's generic model -- takes the measured joint
   positions (its velocities stay internal). As in FZI's code the pose in
   the first error is the model's pose after the previous step (the last
   command: synchronising the joints does not refresh it), while H and J
   are evaluated at the measured joints. Here the default is the measured
   pose (``pose_feedback = "measured"``; ``"command"`` is FZI's choice, see
   :class:`FdccParams`);
2. for each of ``iterations`` internal steps of ``internal_period_s``:

   - the net Cartesian error, in W, ``net = [K (x_d - x) + (f_t - f_m);
     K_rot rotvec(R_d R^T)]``, with x the probe tip, K the diagonal
     stiffness input, f_m the measured force and f_t the target force, both
     in the sensor convention (negative z = the probe pressing into the
     body). ``f_t - f_m`` is FZI's ``F_sensor - F_target`` written with the
     sensor's opposite sign: pressing harder than the target makes f_m more
     negative and the net force push the probe up;
   - a PD on each of the six components, FZI's ``p e + d (e - e_prev)/dt``
     with dt the internal period, times ``error_scale``;
   - forward dynamics of the model, ``qdd = H(q)^-1 J(q)^T u`` (J the
     probe's spatial Jacobian in W, u ordered as Drake's ``[tau; f]``);
   - explicit Euler: ``q += qd dt``, ``qd = velocity_decay (qd + qdd dt)``,
     positions clamped to the joint limits (velocity into a limit zeroed);

3. the resulting q is the joint position command.

Everything here is plain Python arithmetic (numpy and LAPACK for the 6x6
products and solve) on a MultibodyPlant context that the caller builds
(:func:`vic_drake.models.ur3e.MakeFdccModel`); the LeafSystem
(:class:`vic_drake.systems.fdcc.FdccController`) holds the state.
:func:`fdcc_step` is the checked entry point; :func:`fdcc_tick` is the same
tick on float64 arrays with the settings already in :class:`FdccConstants`.

The settings are :class:`~vic_drake.control.fdcc_params.FdccParams`
(re-exported here).
"""

from dataclasses import dataclass
from math import isfinite
from typing import NamedTuple

import numpy as np
from pydrake.math import RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable, SpatialInertia, UnitInertia
from scipy.linalg.lapack import dgesv

from vic_drake.control.fdcc_params import FdccParams
from vic_drake.errors import VicDrakeError


class FdccModel:
    """FZI's generic internal model of the arm (see the module docstring).

    Holds a MultibodyPlant and a scratch context whose positions are written
    before every use; it carries no state between calls. The caller builds
    the plant (:func:`vic_drake.models.ur3e.MakeFdccModel` for the UR3e);
    this class gives every moving link (the child body of each joint with
    velocities) the light inertia of ``params`` in its context.
    """

    def __init__(self, params: FdccParams, plant: MultibodyPlant, frame):
        """
        Args:
            params: the FDCC settings (link mass and inertia).
            plant: a finalized MultibodyPlant of the arm, its end-effector
                body already carrying the model's end-effector inertia.
            frame: the end-effector frame of ``plant`` (the probe frame P).
        """
        if not plant.is_finalized():
            raise VicDrakeError("FdccModel needs a finalized MultibodyPlant")
        context = plant.CreateDefaultContext()
        light = SpatialInertia(
            params.link_mass_kg,
            np.zeros(3),
            UnitInertia.TriaxiallySymmetric(
                params.link_inertia_kg_m2 / params.link_mass_kg
            ),
        )
        for index in plant.GetJointIndices():
            joint = plant.get_joint(index)
            if joint.num_velocities() > 0:
                joint.child_body().SetSpatialInertiaInBodyFrame(context, light)
        self.plant = plant
        self.ur3e = frame.body().model_instance()
        self.frame = frame
        self._context = context
        self._world = plant.world_frame()
        self._p_origin = np.zeros(3)
        self.q_lower = plant.GetPositionLowerLimits()
        self.q_upper = plant.GetPositionUpperLimits()
        # The per-tick calls, bound once.
        self._set_positions = plant.SetPositions
        self._calc_mass_matrix = plant.CalcMassMatrix
        self._calc_jacobian = plant.CalcJacobianSpatialVelocity
        self._calc_pose = frame.CalcPoseInWorld
        self._kV = JacobianWrtVariable.kV
        self._limits = tuple(zip(self.q_lower.tolist(), self.q_upper.tolist()))

    def set_positions(self, q) -> None:
        self._set_positions(self._context, np.asarray(q, float))

    def pose(self, q=None):
        """X_WP of the probe (for q if given, else the last set positions)."""
        if q is not None:
            self._set_positions(self._context, np.asarray(q, float))
        return self._calc_pose(self._context)

    def dynamics(self, q):
        """(X_WP, H (6, 6), J (6, 6) rows [w; v] of the probe in W) at q."""
        context, world = self._context, self._world
        self._set_positions(context, np.asarray(q, float))
        H = self._calc_mass_matrix(context)
        J = self._calc_jacobian(
            context, self._kV, self.frame, self._p_origin, world, world
        )
        return self._calc_pose(context), H, J


class FdccConstants(NamedTuple):
    """The settings one tick reads, as plain floats (:meth:`from_params`)."""

    internal_period_s: float
    error_scale: float
    p_gains: tuple  # 6 floats
    d_gains: tuple  # 6 floats
    rotational_stiffness: tuple  # 3 floats, N m/rad
    velocity_decay: float
    iterations: int
    pose_from_command: bool  # pose_feedback == "command"
    R_WP_target: RotationMatrix

    @classmethod
    def from_params(
        cls, params: FdccParams, R_WP_target: RotationMatrix | None = None
    ) -> "FdccConstants":
        """From ``params`` (as they are now); R_WP_target defaults to params'."""
        return cls(
            float(params.internal_period_s),
            float(params.error_scale),
            tuple(np.asarray(params.p_gains, float).tolist()),
            tuple(np.asarray(params.d_gains, float).tolist()),
            tuple(np.asarray(params.rotational_stiffness_Nm_per_rad, float).tolist()),
            float(params.velocity_decay),
            int(params.iterations),
            params.pose_feedback == "command",
            params.R_WP_target if R_WP_target is None else R_WP_target,
        )


@dataclass(frozen=True)
class FdccStep:
    """One tick's result.

    Attributes:
        q_command: joint position command, rad (6,).
        qdot: internal joint velocity after the tick, rad/s (6,).
        last_error: the PD's previous net error (trans, rot) (6,).
        ok: False when an input or the result was not finite (or a stiffness
            negative); then q_command is the held previous command.
    """

    q_command: np.ndarray
    qdot: np.ndarray
    last_error: np.ndarray
    ok: bool


def _array(name, value, n) -> np.ndarray:
    """value as a new float64 array (n,), or a VicDrakeError naming the argument."""
    a = np.array(value, float)
    if a.shape != (n,):
        raise VicDrakeError(f"{name} must be {n} numbers, got shape {a.shape}")
    return a


def _net_error(X_WP, x_d, R_d, K, K_rot, df) -> list:
    """net_cartesian_error on floats: x_d, K, K_rot, df = f_t - f_m as 3 floats each."""
    t0, t1, t2 = X_WP.translation().tolist()
    aa = (R_d @ X_WP.rotation().inverse()).ToAngleAxis()
    a0, a1, a2 = aa.axis().tolist()
    angle = aa.angle()
    return [
        K[0] * (x_d[0] - t0) + df[0],
        K[1] * (x_d[1] - t1) + df[1],
        K[2] * (x_d[2] - t2) + df[2],
        K_rot[0] * (a0 * angle),
        K_rot[1] * (a1 * angle),
        K_rot[2] * (a2 * angle),
    ]


def net_cartesian_error(
    X_WP,
    p_WP_target,
    R_WP_target,
    stiffness,
    rotational_stiffness,
    measured_force,
    target_force,
) -> np.ndarray:
    """FDCC's net error ``[K e_p + (f_t - f_m); K_rot e_R]`` in W (trans, rot).

    Args:
        X_WP: current probe pose. p_WP_target (3,), R_WP_target: target pose.
        stiffness: diagonal translational stiffness, N/m (3,).
        rotational_stiffness: N m/rad (3,).
        measured_force, target_force: sensor convention (negative z =
            pressing into the body), in W, N (3,).
    """
    f_m = _array("measured_force", measured_force, 3).tolist()
    f_t = _array("target_force", target_force, 3).tolist()
    return np.array(
        _net_error(
            X_WP,
            _array("p_WP_target", p_WP_target, 3).tolist(),
            R_WP_target,
            _array("stiffness", stiffness, 3).tolist(),
            _array("rotational_stiffness", rotational_stiffness, 3).tolist(),
            [f_t[0] - f_m[0], f_t[1] - f_m[1], f_t[2] - f_m[2]],
        )
    )


def fdcc_tick(
    model: FdccModel,
    constants: FdccConstants,
    q,
    q_prev,
    qdot,
    last_error,
    x_d,
    stiffness,
    measured_force,
    target_force,
):
    """One FDCC tick (:func:`fdcc_step`) on float64 arrays; shapes are not checked.

    Arguments as :func:`fdcc_step`'s, in its order, each a 1-D float64 array
    of the right length; pure apart from ``model``'s scratch. Returns
    ``(q_command, qdot, last_error)`` as lists of floats, or None on a fault
    (an input or the result not finite, a negative stiffness, a singular
    mass matrix): the caller then holds ``q_prev`` and zeroes the internal
    velocity and error.
    """
    dt, scale, p_gains, d_gains, K_rot, decay, iterations, from_command, R_d = constants
    qs = q.tolist()
    qd = qdot.tolist()
    err_prev = last_error.tolist()
    xd = x_d.tolist()
    K = stiffness.tolist()
    f_m = measured_force.tolist()
    f_t = target_force.tolist()
    if not all(map(isfinite, qs + qd + err_prev + xd + K + f_m + f_t)) or (
        min(K) < 0.0
    ):
        return None
    if from_command and not all(map(isfinite, q_prev.tolist())):
        return None  # (Drake aborts on a non-finite position.)
    df = [f_t[0] - f_m[0], f_t[1] - f_m[1], f_t[2] - f_m[2]]
    p0, p1, p2, p3, p4, p5 = p_gains
    d0, d1, d2, d3, d4, d5 = d_gains
    for i in range(iterations):
        X_WP, H, J = model.dynamics(q)
        # The pose in the error: FZI's is the model's pose after the previous
        # internal step (the last command; synchronising the joints does not
        # update it), or optionally the measured pose.
        if from_command and i == 0:
            X_WP = model.pose(q_prev)
        err = _net_error(X_WP, xd, R_d, K, K_rot, df)
        # The PD on each component, its output ordered as Drake's [tau; f].
        e0, e1, e2, e3, e4, e5 = err
        g0, g1, g2, g3, g4, g5 = err_prev
        u = np.array(
            [
                scale * (p3 * e3 + d3 * (e3 - g3) / dt),
                scale * (p4 * e4 + d4 * (e4 - g4) / dt),
                scale * (p5 * e5 + d5 * (e5 - g5) / dt),
                scale * (p0 * e0 + d0 * (e0 - g0) / dt),
                scale * (p1 * e1 + d1 * (e1 - g1) / dt),
                scale * (p2 * e2 + d2 * (e2 - g2) / dt),
            ]
        )
        err_prev = err
        # qdd = H^-1 J^T u: LAPACK's LU solve, as np.linalg.solve.
        _, _, qdd, info = dgesv(H, J.T.dot(u))
        if info != 0:  # A singular mass matrix: hold, as for a non-finite result.
            return None
        a0, a1, a2, a3, a4, a5 = qdd.tolist()
        v0, v1, v2, v3, v4, v5 = qd
        x0, x1, x2, x3, x4, x5 = qs
        qs = [
            x0 + v0 * dt,
            x1 + v1 * dt,
            x2 + v2 * dt,
            x3 + v3 * dt,
            x4 + v4 * dt,
            x5 + v5 * dt,
        ]
        qd = [
            decay * (v0 + a0 * dt),
            decay * (v1 + a1 * dt),
            decay * (v2 + a2 * dt),
            decay * (v3 + a3 * dt),
            decay * (v4 + a4 * dt),
            decay * (v5 + a5 * dt),
        ]
        for j, (lower, upper) in enumerate(model._limits):
            if qs[j] < lower:
                qs[j] = lower
                if qd[j] < 0.0:
                    qd[j] = 0.0
            elif qs[j] > upper:
                qs[j] = upper
                if qd[j] > 0.0:
                    qd[j] = 0.0
        if i + 1 < iterations:
            q = np.array(qs)
    if not all(map(isfinite, qs + qd + err_prev)):
        return None
    return qs, qd, err_prev


def fdcc_step(
    model: FdccModel,
    params: FdccParams,
    *,
    q_measured,
    q_command_prev,
    qdot,
    last_error,
    p_WP_target,
    stiffness,
    measured_force,
    target_force,
    R_WP_target: RotationMatrix | None = None,
) -> FdccStep:
    """One FDCC controller tick (module docstring). Pure apart from ``model``'s scratch.

    Args:
        model: the internal model.
        params: the FDCC settings.
        q_measured: measured joint positions, rad (6,).
        q_command_prev: the previous command, rad (6,) (held on a fault).
        qdot: internal joint velocity, rad/s (6,).
        last_error: the PD's previous net error (6,).
        p_WP_target: target probe tip position in W, m (3,).
        stiffness: diagonal translational stiffness, N/m (3,), >= 0.
        measured_force, target_force: in W, sensor convention, N (3,).
        R_WP_target: the orientation target; default ``params.R_WP_target``
            (pass it to save rebuilding it every tick).

    Raises:
        VicDrakeError: an argument of the wrong length.
    """
    arrays = [
        _array(name, value, n)
        for name, value, n in (
            ("q_measured", q_measured, 6),
            ("q_command_prev", q_command_prev, 6),
            ("qdot", qdot, 6),
            ("last_error", last_error, 6),
            ("p_WP_target", p_WP_target, 3),
            ("stiffness", stiffness, 3),
            ("measured_force", measured_force, 3),
            ("target_force", target_force, 3),
        )
    ]
    result = fdcc_tick(model, FdccConstants.from_params(params, R_WP_target), *arrays)
    if result is None:
        return FdccStep(arrays[1], np.zeros(6), np.zeros(6), False)
    q, qd, err = result
    return FdccStep(np.array(q), np.array(qd), np.array(err), True)


__all__ = [
    "FdccConstants",
    "FdccModel",
    "FdccParams",
    "FdccStep",
    "fdcc_step",
    "fdcc_tick",
    "net_cartesian_error",
]
