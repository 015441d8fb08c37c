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

Everything here is plain numpy on a MultibodyPlant context that the caller
builds (:func:`vic_drake.models.ur3e.MakeFdccModel`); the LeafSystem
(:class:`vic_drake.systems.fdcc.FdccController`) holds the state.

:class:`FdccParams` is a mutable dataclass loadable by Drake's
``yaml_load_typed`` (which fills a default instance field by field), so it
validates in ``__post_init__`` and again in :meth:`FdccParams.validate`. (No
``from __future__ import annotations`` here: the YAML loader reads the field
types at run time.)
"""

from dataclasses import dataclass, field

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable, SpatialInertia, UnitInertia
from scipy.linalg.lapack import dgesv

from vic_drake.errors import VicDrakeError


def _check_vec(name, value, n, *, nonneg=False):
    a = np.asarray(value, float)
    if a.shape != (n,) or not np.all(np.isfinite(a)) or (nonneg and np.any(a < 0)):
        what = "non-negative " if nonneg else ""
        raise VicDrakeError(
            f"FdccParams.{name} must be {n} finite {what}numbers, got {value!r}"
        )


@dataclass
class FdccParams:
    """Settings of the FDCC layer (the real rig's, from the published source).

    Gains are ordered (trans x, trans y, trans z, rot x, rot y, rot z) in W.
    """

    period_s: float = 0.002  # Controller tick, s (500 Hz, the UR3e's rate).
    internal_period_s: float = 0.02  # Simulated time per internal step, s (FZI: 0.02).
    iterations: int = 1  # Internal steps per tick.
    error_scale: float = 0.5  # Scales the PD output (solver.error_scale).
    # Proportional gains of the Cartesian PD (x, y: 0.05; z: 0.3; rotation: 1.5).
    p_gains: list[float] = field(
        default_factory=lambda: [0.05, 0.05, 0.3, 1.5, 1.5, 1.5]
    )
    # Derivative gains, s (x, y: 0.005; z: 0.01; rotation: none).
    d_gains: list[float] = field(
        default_factory=lambda: [0.005, 0.005, 0.01, 0.0, 0.0, 0.0]
    )
    # Rotational stiffness about x, y, z of W, N m/rad.
    rotational_stiffness_Nm_per_rad: list[float] = field(
        default_factory=lambda: [50.0, 50.0, 50.0]
    )
    # Mass of each moving link of the model, kg (FZI default).
    link_mass_kg: float = 0.1
    link_inertia_kg_m2: float = 1e-6  # Their rotational inertia, kg m^2.
    end_effector_mass_kg: float = 1.0  # Model mass at the probe frame, kg.
    end_effector_inertia_kg_m2: float = 1.0  # Its rotational inertia, kg m^2.
    # Internal velocity factor per step (FZI: 10 % damping).
    velocity_decay: float = 0.9
    # Target orientation of the probe frame, quaternion (w, x, y, z): pointing down.
    target_orientation_wxyz: list[float] = field(
        default_factory=lambda: [0.0, 1.0, 0.0, 0.0]
    )
    # Pose in the Cartesian error: "measured" (of the synchronised measured
    # joints) or "command" (FZI: the model's pose after the previous tick's
    # step, i.e. of the last command). H and J use the measured joints in
    # both. Default "measured": with this simulation's trailing joint servo,
    # "command" makes a VS-VF replay ring; see docs/decisions.md, "FDCC pose
    # feedback".
    pose_feedback: str = "measured"

    def __post_init__(self):
        self.validate()

    def validate(self) -> "FdccParams":
        """Checks every field; raises VicDrakeError naming the bad one. Returns self."""
        for name in (
            "period_s",
            "internal_period_s",
            "error_scale",
            "link_mass_kg",
            "link_inertia_kg_m2",
            "end_effector_mass_kg",
            "end_effector_inertia_kg_m2",
        ):
            value = getattr(self, name)
            if not (
                isinstance(value, (int, float)) and np.isfinite(value) and value > 0
            ):
                raise VicDrakeError(
                    f"FdccParams.{name} must be a number > 0, got {value!r}"
                )
        it = self.iterations
        if isinstance(it, bool) or not isinstance(it, (int, np.integer)) or it < 1:
            raise VicDrakeError(
                f"FdccParams.iterations must be an integer >= 1, got {it!r}"
            )
        if not (0 < self.velocity_decay <= 1):
            raise VicDrakeError(
                f"FdccParams.velocity_decay must be in (0, 1], got {self.velocity_decay!r}"
            )
        if self.pose_feedback not in ("command", "measured"):
            raise VicDrakeError(
                "FdccParams.pose_feedback must be 'command' or 'measured', got "
                f"{self.pose_feedback!r}"
            )
        _check_vec("p_gains", self.p_gains, 6, nonneg=True)
        _check_vec("d_gains", self.d_gains, 6, nonneg=True)
        _check_vec(
            "rotational_stiffness_Nm_per_rad",
            self.rotational_stiffness_Nm_per_rad,
            3,
            nonneg=True,
        )
        _check_vec("target_orientation_wxyz", self.target_orientation_wxyz, 4)
        if not np.linalg.norm(self.target_orientation_wxyz) > 0.5:
            raise VicDrakeError(
                "FdccParams.target_orientation_wxyz must be a unit quaternion (w, x, y, z), "
                f"got {self.target_orientation_wxyz!r}"
            )
        return self

    @property
    def R_WP_target(self) -> RotationMatrix:
        """The target orientation of the probe frame."""
        w, x, y, z = np.asarray(self.target_orientation_wxyz, float)
        q = np.array([w, x, y, z]) / np.linalg.norm([w, x, y, z])
        return RotationMatrix(Quaternion(q))


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

    def set_positions(self, q) -> None:
        self.plant.SetPositions(self._context, np.asarray(q, float))

    def pose(self, q=None):
        """X_WP of the probe (for q if given, else the last set positions)."""
        if q is not None:
            self.set_positions(q)
        return self.frame.CalcPoseInWorld(self._context)

    def dynamics(self, q):
        """(X_WP, H (6, 6), J (6, 6) rows [w; v] of the probe in W) at q."""
        self.set_positions(q)
        H = self.plant.CalcMassMatrix(self._context)
        J = self.plant.CalcJacobianSpatialVelocity(
            self._context,
            JacobianWrtVariable.kV,
            self.frame,
            self._p_origin,
            self._world,
            self._world,
        )
        return self.frame.CalcPoseInWorld(self._context), H, J


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
    e_p = np.asarray(p_WP_target, float) - X_WP.translation()
    aa = (R_WP_target @ X_WP.rotation().inverse()).ToAngleAxis()
    e_R = aa.axis() * aa.angle()
    force = np.asarray(stiffness, float) * e_p + (
        np.asarray(target_force, float) - np.asarray(measured_force, float)
    )
    return np.concatenate([force, np.asarray(rotational_stiffness, float) * e_R])


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
    """
    q = np.asarray(q_measured, float)
    qd = np.asarray(qdot, float)
    err_prev = np.asarray(last_error, float)
    x_d = np.asarray(p_WP_target, float)
    K = np.asarray(stiffness, float)
    f_m = np.asarray(measured_force, float)
    f_t = np.asarray(target_force, float)
    q_prev = np.asarray(q_command_prev, float)
    # One vectorised check (this runs at 500 Hz).
    inputs = np.concatenate([q, qd, err_prev, x_d, K, f_m, f_t])
    if not np.isfinite(inputs).all() or (K < 0).any():
        return FdccStep(q_prev.copy(), np.zeros(6), np.zeros(6), False)
    dt = params.internal_period_s
    p_gains = np.asarray(params.p_gains, float)
    d_gains = np.asarray(params.d_gains, float)
    R_d = params.R_WP_target if R_WP_target is None else R_WP_target
    K_rot = np.asarray(params.rotational_stiffness_Nm_per_rad, float)
    # The pose in the error: FZI's is the model's pose after the previous
    # internal step (the last command; synchronising the joints does not
    # update it), or optionally the measured pose.
    q_pose = q_prev if params.pose_feedback == "command" else q
    for _ in range(params.iterations):
        X_WP, H, J = model.dynamics(q)
        X_pose = X_WP if q_pose is q else model.pose(q_pose)
        err = net_cartesian_error(X_pose, x_d, R_d, K, K_rot, f_m, f_t)
        u = params.error_scale * (p_gains * err + d_gains * (err - err_prev) / dt)
        err_prev = err
        u_drake = np.concatenate([u[3:], u[:3]])  # [tau; f]
        # LAPACK's LU solve, as np.linalg.solve (same result) without its
        # wrapper's overhead (this runs at 500 Hz).
        _, _, qdd, info = dgesv(H, J.T @ u_drake)
        if info != 0:  # A singular mass matrix: hold, as for a non-finite result.
            return FdccStep(q_prev.copy(), np.zeros(6), np.zeros(6), False)
        q_next = q + qd * dt
        qd = params.velocity_decay * (qd + qdd * dt)
        below, above = q_next < model.q_lower, q_next > model.q_upper
        if below.any() or above.any():
            q_next = np.minimum(np.maximum(q_next, model.q_lower), model.q_upper)
            qd[(below & (qd < 0)) | (above & (qd > 0))] = 0.0
        q = q_pose = q_next
    if not np.isfinite(np.concatenate([q, qd, err_prev])).all():
        return FdccStep(q_prev.copy(), np.zeros(6), np.zeros(6), False)
    return FdccStep(q, qd, err_prev, True)


__all__ = ["FdccModel", "FdccParams", "FdccStep", "fdcc_step", "net_cartesian_error"]
