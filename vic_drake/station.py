"""The simulated rig: UR3e, BOTA SensONE F/T sensor, indenter, chest phantom.

Frames (monogram notation):

- ``W`` -- the world frame, identical to the rig's UR ``base_link`` frame
  (ROS/REP-103 convention: a half turn about z from UR's own ``base``
  frame). The airo-models UR3e URDF's root link *is* ``base_link``, and it
  is welded at W's origin, so the logged positions of the real rig (and the
  phantom map, x from -0.16 to 0.04 m, y about -0.36 m, z about 0.1 m) are
  W coordinates here.
- ``wrist_3_link`` -- the UR's last link (its frame coincides with ``tool0``,
  z out of the flange).
- ``ft_sensor_mount`` (body M) -- the sensor's mounting side, welded to the
  flange at ``wrist_3 * Rz(-pi/2)`` (the rig's ``ft_frame`` = wrist_3 turned
  pi about x, then the mounting turned rpy (pi, 0, pi/2): together a
  quarter turn about z, z still out of the flange).
- ``ft_sensor_wrench`` (body S, frame S) -- the sensor's wrench side; S is
  the sensor's wrench frame, ``ft_wrench_offset_m`` (0.035 m) along M's z.
  M and S are joined by the weld ``ft_sensor_weld``, whose reaction force
  is the F/T reading (:mod:`vic_drake.systems.ft_sensor`).
- ``indenter`` (body I, frame = S) -- the 3D-printed rigid cone with a
  spherical tip, welded to S.
- ``probe`` (frame P on I) -- the indenter tip, ``indenter_length_m``
  (0.07 m) further along S's z, the lowest point of the tip sphere, with S's
  orientation. The real controller's pose target keeps P pointing straight
  down: ``R_WP = Rx(pi)`` (quaternion x = 1, w = 0), see
  :func:`probe_down_rotation`.
- ``phantom`` (body Ph) -- the chest, on a prismatic z joint
  (``phantom_lift``) at ``phantom_offset_m``; its frame carries the map's
  coordinates, so with zero lift and offset the map is in W.

Forces: the tissue's push on the indenter is the Hunt-Crossley element of
:mod:`vic_drake.systems.tissue_force` (Drake contact between the indenter
and the phantom is filtered out). Robot links and the sensor housing have
coarse rigid hydroelastic geometry that meets the phantom's compliant
hydroelastic volume mesh (:mod:`vic_drake.models.phantom_mesh`): a safety
contact, not the measured force.

The arm is position controlled, as the real UR3e: the streamed joint
command (500 Hz) is smoothed by a first-order filter (``servo_time_constant_s``
0.03 s, the UR driver's servoj lookahead) and, with an integral of the
tracking error (``servo_integral_time_s``), is the desired state of Drake's
implicit PD actuators (``JointActuator.set_controller_gains``, gains
``joint_kp_Nm_per_rad``/``joint_kd_Nms_per_rad``), with the arm's gravity
torques as feed-forward (the UR controller compensates gravity itself).
Effort limits are the URDF's (56, 56, 28, 12, 12, 12 N m). The servo lag
matters: FDCC re-reads the measured joints every tick, and with an ideal
servo the FZI gains' force loop is unstable against the sensor's 56 ms lag.

Notes for users: the plant's output ports are sampled (Drake's default for
discrete plants), so ``plant.contact_results`` and the reaction forces
behind the F/T reading describe the last plant step -- take one step after
setting a state by hand. The sensor noise comes from a ``RandomSource``
whose seed lives in the Context (deterministic by default; call
``diagram.SetRandomContext(context, RandomGenerator(seed))`` for another
draw). Speed (``benchmarks/bench_station.py``, ``benchmarks/bench_scan.py``):
the plant steps every 2 ms with the command, so each Python LeafSystem
(tissue force and tip kinematics, sensor, servo filter; in a scan the
controller and FDCC) runs once per step.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from airo_models import get_urdf_path
from pydrake.common import RandomDistribution
from pydrake.common.eigen_geometry import Quaternion
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    CollisionFilterDeclaration,
    Cylinder,
    GeometrySet,
    Mesh,
    ProximityProperties,
    RoleAssign,
    Sphere,
)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlant,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    ModelInstanceIndex,
    PdControllerGains,
    PrismaticJoint,
    RotationalInertia,
    SpatialInertia,
    UnitInertia,
    WeldJoint,
)
from pydrake.solvers import Solve
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import (
    Demultiplexer,
    LinearSystem,
    MatrixGain,
    Multiplexer,
    RandomSource,
    StateInterpolatorWithDiscreteDerivative,
)

from vic_drake.errors import VicDrakeError
from vic_drake.models.phantom_mesh import phantom_mesh_paths
from vic_drake.systems.ft_sensor import ForceTorqueSensor
from vic_drake.systems.tissue_force import TissueForceElement
from vic_drake.tissue import Phantom

#: The UR3e's six joints, in the order of every q vector in vic_drake.
UR3E_JOINTS = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)

#: A configuration with the probe pointing down over the phantom (IK seed).
DEFAULT_Q_SEED = (-2.1, -1.4, 1.7, -1.87, -1.57, -2.1)
#: Further seeds tried when no q_seed is given and DEFAULT_Q_SEED fails
#: (arm stretched out, arm pulled in, elbow-up home).
FALLBACK_Q_SEEDS = (
    (-2.1, -0.9, 0.9, -1.57, -1.57, -2.1),
    (-2.1, -1.9, 2.4, -2.07, -1.57, -2.1),
    (-1.57, -1.57, 1.57, -1.57, -1.57, 0.0),
)


def probe_down_rotation() -> RotationMatrix:
    """R_WP of the real controller's target: quaternion (w, x, y, z) = (0, 1, 0, 0)."""
    return RotationMatrix(Quaternion(0.0, 1.0, 0.0, 0.0))


def _vec(value, n, name):
    a = np.asarray(value, float)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise VicDrakeError(
            f"StationParams.{name} must be {n} finite numbers, got {value!r}"
        )
    return a


@dataclass
class StationParams:
    """Everything the simulated rig is made of (SI units).

    Defaults: the UR3e and tool of the paper's rig; sensor noise estimated
    from the free-air samples (penetration < -3 mm) of the real 31-column
    logs (std 0.055, 0.055, 0.045 N in x, y, z; nearly white).

    Sensor lag: none by default. The logs show the force trailing the
    logged pose by 28 ticks (56 ms), but that delay is not in the real
    control loop: replaying the real experiments on the measured map with
    ``sensor_lag_samples=28`` inside the loop makes the FDCC force loop ring
    at about 2.5 Hz over the stiff ribs (test_tracking5: force RMSE against
    the log 1.51 N, K_z correlation 0.67; test_nardi_matForce_lowR: 2.34 N,
    0.51), which the real rig did not do; without it the same runs match the
    logs (0.30 N, 0.89; 0.65 N, 0.76). The logged pose is most likely the
    FDCC's command, which the arm follows with the servo's delay, so the
    56 ms sit between the logged pose and the motion, not in the sensor.
    Set 28 to study a lagging sensor.

    Plant step: 2 ms, the command and sensor period, so every plant step
    meets one controller tick (the scans run about 1.5x faster than with
    1 ms). The tissue force is explicit over a step; with 2 ms the closed
    loop's force and penetration stay within noise of the 1 ms runs
    (golden scan metrics, the static press test, compare-real on the real
    logs, measured).
    """

    # -- plant ---------------------------------------------------------------
    time_step_s: float = 0.002  # MultibodyPlant discrete step, s.
    contact_approximation: str = "sap"  # Discrete contact solver: "sap" or "lagged".
    gravity_m_per_s2: float = 9.81  # Gravity magnitude (along -z of W), m/s^2.
    # -- UR3e joint position servo (implicit PD actuators) ---------------------
    # Stiffness per joint, N m/rad: with the gravity feed-forward alone (no
    # integral) a 9 N tip load leaves 0.4 mm of static error; the servo's
    # integral action removes it.
    joint_kp_Nm_per_rad: tuple[float, ...] = (
        8000.0,
        8000.0,
        4000.0,
        1000.0,
        1000.0,
        1000.0,
    )
    # Damping per joint, N m s/rad (about critical for the arm's inertia).
    joint_kd_Nms_per_rad: tuple[float, ...] = (120.0, 120.0, 60.0, 8.0, 8.0, 8.0)
    command_period_s: float = 0.002  # Period of the position command (500 Hz), s.
    # Time constant of the command smoothing, s: the UR driver's servoj
    # lookahead_time (0.03 s); the arm tracks commands with this lag.
    servo_time_constant_s: float = 0.03
    # Integral time of the servo's tracking-error integral, s (0 = none):
    # removes the static error a load would leave with the PD alone.
    servo_integral_time_s: float = 0.05
    # -- BOTA SensONE F/T sensor ---------------------------------------------
    ft_mount_mass_kg: float = 0.149  # Mounting-side mass, kg.
    ft_wrench_mass_kg: float = 0.081  # Wrench-side mass, kg.
    ft_wrench_offset_m: float = (
        0.035  # Wrench frame S from the mounting face along z, m.
    )
    ft_radius_m: float = 0.04  # Housing radius (geometry and inertia), m.
    sensor_period_s: float = 0.002  # Sampling period, s (500 Hz).
    sensor_lag_samples: int = 0  # Reading delay, samples (0: see the class doc).
    # Noise std of the force components (x, y, z) in S, N.
    sensor_noise_std_N: tuple[float, float, float] = (0.055, 0.055, 0.045)
    sensor_torque_noise_std_Nm: float = 0.0  # Torque noise std, N m (not in the logs).
    sensor_bias_N: tuple[float, float, float] = (0.0, 0.0, 0.0)  # Force bias in S, N.
    # -- indenter (3D-printed rigid cone with a spherical tip) -----------------
    indenter_mass_kg: float = 0.04  # Mass, kg (PLA, about 30 cm^3).
    indenter_length_m: float = 0.07  # Probe tip from the wrench frame along z, m.
    indenter_tip_radius_m: float = 0.02  # Radius of the spherical tip, m.
    # -- phantom ----------------------------------------------------------------
    phantom_offset_m: tuple[float, float, float] = (
        0.0,
        0.0,
        0.0,
    )  # Map frame in W at zero lift, m.
    phantom_mass_kg: float = 5.0  # Mass of the lifted phantom, kg.
    phantom_kp_N_per_m: float = (
        2.0e6  # Lift servo stiffness, N/m (sinks 4 um under 8 N).
    )
    phantom_kd_Ns_per_m: float = 6.0e3  # Lift servo damping, N s/m (about critical).
    phantom_mesh_resolution_m: float = 0.015  # Grid spacing of the contact mesh, m.
    phantom_thickness_m: float = 0.05  # Slab below the lowest surface point, m.
    hydroelastic_modulus_Pa: float = 1.0e5  # Phantom's hydroelastic modulus, Pa.
    hydroelastic_resolution_hint_m: float = (
        0.03  # Tessellation of rigid link shapes, m.
    )
    hunt_crossley_dissipation_s_per_m: float = 5.0  # Drake contact dissipation, s/m.
    friction_coefficient: float = 0.5  # Coulomb friction of the safety contact.
    robot_contact: bool = True  # Robot links and sensor collide with the phantom.
    # Sliding friction of the tissue on the tip (times the HC force; 0 = the
    # paper's 1-D model). metrics.estimate_tissue_friction on the real VS
    # scans' lateral sensor forces: 0.215 (test_nardi_matForce_lowR), 0.299
    # (test_tracking5).
    tissue_friction_coefficient: float = 0.25
    tissue_slip_speed_m_per_s: float = (
        0.005  # Regularisation speed of that friction, m/s.
    )
    # Tissue force along the surface normal (True) or vertical (False, the
    # paper's 1-D model). The real scans' lateral forces follow the normal:
    # tilt 1.04 and 0.82 of it (metrics.estimate_tissue_friction), and with
    # the normal and the friction compare-real's K_z correlation on the
    # VS-VF log rises from 0.76 to about 0.9.
    tissue_force_along_normal: bool = True
    # Grid of the force element's per-step lookup of non-grid phantoms, m
    # (a GridPhantom is looked up on its own grid).
    tissue_lookup_resolution_m: float = 0.0005

    def __post_init__(self):
        positive = (
            "time_step_s",
            "gravity_m_per_s2",
            "command_period_s",
            "servo_time_constant_s",
            "ft_mount_mass_kg",
            "ft_wrench_mass_kg",
            "ft_wrench_offset_m",
            "ft_radius_m",
            "sensor_period_s",
            "indenter_mass_kg",
            "indenter_length_m",
            "indenter_tip_radius_m",
            "phantom_mass_kg",
            "phantom_kp_N_per_m",
            "phantom_mesh_resolution_m",
            "phantom_thickness_m",
            "hydroelastic_modulus_Pa",
            "hydroelastic_resolution_hint_m",
            "tissue_lookup_resolution_m",
            "tissue_slip_speed_m_per_s",
        )
        for name in positive:
            value = getattr(self, name)
            if not (
                isinstance(value, (int, float)) and np.isfinite(value) and value > 0
            ):
                raise VicDrakeError(
                    f"StationParams.{name} must be a number > 0, got {value!r}"
                )
        nonneg = (
            "servo_integral_time_s",
            "sensor_torque_noise_std_Nm",
            "phantom_kd_Ns_per_m",
            "hunt_crossley_dissipation_s_per_m",
            "friction_coefficient",
            "tissue_friction_coefficient",
        )
        for name in nonneg:
            value = getattr(self, name)
            if not (
                isinstance(value, (int, float)) and np.isfinite(value) and value >= 0
            ):
                raise VicDrakeError(
                    f"StationParams.{name} must be a number >= 0, got {value!r}"
                )
        if self.contact_approximation not in ("sap", "lagged"):
            raise VicDrakeError(
                "StationParams.contact_approximation must be 'sap' or 'lagged', got "
                f"{self.contact_approximation!r}"
            )
        kp = _vec(self.joint_kp_Nm_per_rad, 6, "joint_kp_Nm_per_rad")
        kd = _vec(self.joint_kd_Nms_per_rad, 6, "joint_kd_Nms_per_rad")
        if np.any(kp <= 0) or np.any(kd < 0):
            raise VicDrakeError(
                "StationParams.joint_kp_Nm_per_rad must be > 0 and joint_kd_Nms_per_rad >= 0, "
                f"got {self.joint_kp_Nm_per_rad!r}, {self.joint_kd_Nms_per_rad!r}"
            )
        noise = _vec(self.sensor_noise_std_N, 3, "sensor_noise_std_N")
        if np.any(noise < 0):
            raise VicDrakeError(
                f"StationParams.sensor_noise_std_N must be >= 0, got {self.sensor_noise_std_N!r}"
            )
        _vec(self.sensor_bias_N, 3, "sensor_bias_N")
        _vec(self.phantom_offset_m, 3, "phantom_offset_m")
        lag = self.sensor_lag_samples
        if isinstance(lag, bool) or not isinstance(lag, (int, np.integer)) or lag < 0:
            raise VicDrakeError(
                f"StationParams.sensor_lag_samples must be an integer >= 0, got {lag!r}"
            )
        if self.indenter_tip_radius_m >= self.indenter_length_m:
            raise VicDrakeError(
                f"StationParams.indenter_tip_radius_m ({self.indenter_tip_radius_m}) must be "
                f"< indenter_length_m ({self.indenter_length_m})"
            )
        for name in ("robot_contact", "tissue_force_along_normal"):
            if not isinstance(getattr(self, name), bool):
                raise VicDrakeError(
                    f"StationParams.{name} must be a bool, got {getattr(self, name)!r}"
                )

    # Tool geometry used by several builders.
    @property
    def X_W3M(self) -> RigidTransform:
        """Pose of the sensor mounting frame M in wrist_3_link."""
        return RigidTransform(RotationMatrix.MakeZRotation(-np.pi / 2), np.zeros(3))

    @property
    def p_MP(self) -> np.ndarray:
        """Probe tip P from the mounting frame M, in M, m."""
        return np.array([0.0, 0.0, self.ft_wrench_offset_m + self.indenter_length_m])

    @property
    def distal_mass_kg(self) -> float:
        """Mass the sensor carries (wrench side + indenter), kg."""
        return self.ft_wrench_mass_kg + self.indenter_mass_kg


# ----------------------------------------------------------------------------
# Model building blocks
# ----------------------------------------------------------------------------


@dataclass
class ArmHandles:
    """Handles of the arm and tool added to a plant."""

    plant: MultibodyPlant
    ur3e: ModelInstanceIndex
    tool: ModelInstanceIndex | None = None
    probe_frame: object = None
    sensor_weld: object = None
    sensor_body: object = None
    indenter_body: object = None
    mount_body: object = None
    tool_geometries: dict = field(default_factory=dict)


def AddUr3e(plant: MultibodyPlant) -> ModelInstanceIndex:
    """Adds the airo-models UR3e with ``base_link`` welded at W's origin."""
    parser = Parser(plant)
    parser.SetAutoRenaming(True)
    (ur3e,) = parser.AddModels(str(get_urdf_path("ur3e")))
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base_link", ur3e))
    return ur3e


def _cylinder_inertia(mass, radius, length, p_com) -> SpatialInertia:
    """Solid cylinder along z with its centre of mass at p_com (body frame)."""
    ixx = mass * (3 * radius**2 + length**2) / 12
    izz = mass * radius**2 / 2
    return SpatialInertia.MakeFromCentralInertia(
        mass, np.asarray(p_com, float), RotationalInertia(ixx, ixx, izz)
    )


def AddTool(
    plant: MultibodyPlant,
    ur3e: ModelInstanceIndex,
    params: StationParams,
    *,
    with_geometry: bool = True,
) -> ArmHandles:
    """Adds the F/T sensor (two bodies and their weld), indenter and probe frame.

    Masses: mounting side ``ft_mount_mass_kg``, wrench side
    ``ft_wrench_mass_kg`` (SensONE, 0.149 / 0.081 kg) and the indenter
    ``indenter_mass_kg``. The indenter is modelled as a cylinder of the tip
    radius down to the tip sphere's centre plus the tip sphere (a simplified
    7 cm cone).
    """
    tool = plant.AddModelInstance("tool")
    p = params
    half = p.ft_wrench_offset_m / 2
    mount = plant.AddRigidBody(
        "ft_sensor_mount",
        tool,
        _cylinder_inertia(p.ft_mount_mass_kg, p.ft_radius_m, half, [0, 0, half / 2]),
    )
    plant.WeldFrames(
        plant.GetFrameByName("wrist_3_link", ur3e), mount.body_frame(), p.X_W3M
    )
    wrench = plant.AddRigidBody(
        "ft_sensor_wrench",
        tool,
        _cylinder_inertia(p.ft_wrench_mass_kg, p.ft_radius_m, half, [0, 0, -half / 2]),
    )
    mount_S = plant.AddFrame(
        FixedOffsetFrame(
            "ft_sensor_wrench_on_mount",
            mount.body_frame(),
            RigidTransform([0, 0, p.ft_wrench_offset_m]),
        )
    )
    weld = plant.AddJoint(
        WeldJoint("ft_sensor_weld", mount_S, wrench.body_frame(), RigidTransform())
    )
    r, L = p.indenter_tip_radius_m, p.indenter_length_m
    indenter = plant.AddRigidBody(
        "indenter", tool, _cylinder_inertia(p.indenter_mass_kg, r, L, [0, 0, 0.4 * L])
    )
    plant.WeldFrames(wrench.body_frame(), indenter.body_frame(), RigidTransform())
    probe = plant.AddFrame(
        FixedOffsetFrame("probe", indenter.body_frame(), RigidTransform([0, 0, L]))
    )
    handles = ArmHandles(
        plant=plant,
        ur3e=ur3e,
        tool=tool,
        probe_frame=probe,
        sensor_weld=weld,
        sensor_body=wrench,
        indenter_body=indenter,
        mount_body=mount,
    )
    if with_geometry and plant.geometry_source_is_registered():
        grey, blue = np.array([0.3, 0.3, 0.3, 1.0]), np.array([0.2, 0.4, 0.9, 1.0])
        housing = Cylinder(p.ft_radius_m, half)
        shapes = {
            "mount": (mount, housing, RigidTransform([0, 0, half / 2]), grey),
            "wrench": (wrench, housing, RigidTransform([0, 0, -half / 2]), grey),
            "indenter_cone": (
                indenter,
                Cylinder(r, L - r),
                RigidTransform([0, 0, (L - r) / 2]),
                blue,
            ),
            "indenter_tip": (indenter, Sphere(r), RigidTransform([0, 0, L - r]), blue),
        }
        for name, (body, shape, X_BG, color) in shapes.items():
            plant.RegisterVisualGeometry(body, X_BG, shape, f"{name}_visual", color)
            props = ProximityProperties()
            AddRigidHydroelasticProperties(p.hydroelastic_resolution_hint_m, props)
            AddContactMaterial(
                p.hunt_crossley_dissipation_s_per_m,
                None,
                CoulombFriction(p.friction_coefficient, p.friction_coefficient),
                props,
            )
            handles.tool_geometries[name] = plant.RegisterCollisionGeometry(
                body, X_BG, shape, f"{name}_collision", props
            )
    return handles


def MakeUr3ePlant(
    params: StationParams | None = None, *, time_step: float = 0.0
) -> tuple[MultibodyPlant, ArmHandles]:
    """A finalized plant of the UR3e with the tool and ``probe`` frame only.

    For inverse kinematics and analysis (no phantom, no scene graph).
    """
    params = params or StationParams()
    plant = MultibodyPlant(time_step)
    ur3e = AddUr3e(plant)
    handles = AddTool(plant, ur3e, params, with_geometry=False)
    plant.Finalize()
    return plant, handles


# ----------------------------------------------------------------------------
# Inverse kinematics
# ----------------------------------------------------------------------------


def solve_tip_ik(
    p_WP,
    *,
    q_seed=None,
    params: StationParams | None = None,
    R_WP: RotationMatrix | None = None,
    position_tolerance_m: float = 1e-6,
    angle_tolerance_rad: float = 1e-6,
) -> np.ndarray:
    """Joint angles placing the probe tip at p_WP with the tool pointing down.

    Solves Drake's InverseKinematics (nearest to ``q_seed`` in the joint
    norm) for the probe frame at ``p_WP`` with orientation ``R_WP`` (default
    :func:`probe_down_rotation`).

    Args:
        p_WP: tip position in W (the rig's base_link), m (3,).
        q_seed: initial guess and cost centre, rad (6,); default
            DEFAULT_Q_SEED, then FALLBACK_Q_SEEDS if that fails.
        params: station geometry (tool length); default StationParams().
        R_WP: tip orientation; default pointing straight down.
        position_tolerance_m, angle_tolerance_rad: constraint tolerances.

    Returns:
        q (6,), rad, in :data:`UR3E_JOINTS` order.

    Raises:
        VicDrakeError: p_WP is not finite or the pose is unreachable.
    """
    p_WP = np.asarray(p_WP, float)
    if p_WP.shape != (3,) or not np.all(np.isfinite(p_WP)):
        raise VicDrakeError(f"p_WP must be 3 finite numbers (m), got {p_WP!r}")
    seeds = [DEFAULT_Q_SEED, *FALLBACK_Q_SEEDS] if q_seed is None else [q_seed]
    seeds = [np.asarray(seed, float) for seed in seeds]
    if seeds[0].shape != (6,) or not np.all(np.isfinite(seeds[0])):
        raise VicDrakeError(
            f"q_seed must be 6 finite joint angles (rad), got {q_seed!r}"
        )
    plant, handles = MakeUr3ePlant(params)
    R_WP = R_WP or probe_down_rotation()
    ik = InverseKinematics(plant)
    tol = np.full(3, position_tolerance_m)
    ik.AddPositionConstraint(
        handles.probe_frame, np.zeros(3), plant.world_frame(), p_WP - tol, p_WP + tol
    )
    ik.AddOrientationConstraint(
        plant.world_frame(),
        R_WP,
        handles.probe_frame,
        RotationMatrix(),
        angle_tolerance_rad,
    )
    prog = ik.get_mutable_prog()
    q = ik.q()
    cost = prog.AddQuadraticErrorCost(np.eye(6), seeds[0], q)
    for seed in seeds:
        cost.evaluator().UpdateCoefficients(2 * np.eye(6), -2 * seed, seed @ seed)
        prog.SetInitialGuess(q, seed)
        result = Solve(prog)
        if result.is_success():
            return result.GetSolution(q)
    raise VicDrakeError(
        f"no joint configuration puts the probe tip at {p_WP.tolist()} m pointing down "
        f"(solver {result.get_solver_id().name()}, {len(seeds)} seed(s)); the UR3e "
        "reaches about 0.5 m from its shoulder"
    )


def initial_q_for_tip(p_WP, params: StationParams | None = None) -> np.ndarray:
    """Joint angles for a start tip position, probe pointing down (IK from the seed)."""
    return solve_tip_ik(p_WP, params=params)


def probe_pose(q, params: StationParams | None = None) -> RigidTransform:
    """Forward kinematics: X_WP of the probe tip for joint angles q (6,)."""
    plant, handles = MakeUr3ePlant(params)
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, handles.ur3e, np.asarray(q, float))
    return handles.probe_frame.CalcPoseInWorld(context)


# ----------------------------------------------------------------------------
# The station diagram
# ----------------------------------------------------------------------------


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


def _add_phantom(plant, params: StationParams, phantom: Phantom):
    model = plant.AddModelInstance("phantom")
    x_min, x_max, y_min, y_max = phantom.bounds
    size = np.array([x_max - x_min, y_max - y_min, params.phantom_thickness_m])
    body = plant.AddRigidBody(
        "phantom",
        model,
        SpatialInertia(
            params.phantom_mass_kg,
            np.zeros(3),
            UnitInertia.SolidBox(*size),
        ),
    )
    frame_on_world = plant.AddFrame(
        FixedOffsetFrame(
            "phantom_base", plant.world_frame(), RigidTransform(params.phantom_offset_m)
        )
    )
    joint = plant.AddJoint(
        PrismaticJoint("phantom_lift", frame_on_world, body.body_frame(), [0, 0, 1])
    )
    actuator = plant.AddJointActuator("phantom_lift_actuator", joint)
    actuator.set_controller_gains(
        PdControllerGains(p=params.phantom_kp_N_per_m, d=params.phantom_kd_Ns_per_m)
    )
    vtk, obj = phantom_mesh_paths(
        phantom,
        resolution_m=params.phantom_mesh_resolution_m,
        thickness_m=params.phantom_thickness_m,
    )
    props = ProximityProperties()
    AddCompliantHydroelasticProperties(
        params.phantom_mesh_resolution_m, params.hydroelastic_modulus_Pa, props
    )
    AddContactMaterial(
        params.hunt_crossley_dissipation_s_per_m,
        None,
        CoulombFriction(params.friction_coefficient, params.friction_coefficient),
        props,
    )
    geometry = plant.RegisterCollisionGeometry(
        body, RigidTransform(), Mesh(str(vtk)), "phantom_collision", props
    )
    plant.RegisterVisualGeometry(
        body, RigidTransform(), Mesh(str(obj)), "phantom_visual", [0.9, 0.75, 0.65, 1.0]
    )
    return model, body, geometry


def _make_links_hydroelastic(plant, scene_graph, ur3e, params):
    """Gives the URDF's primitive link collisions coarse rigid hydroelastic properties."""
    ids = []
    for body_index in plant.GetBodyIndices(ur3e):
        for gid in plant.GetCollisionGeometriesForBody(plant.get_body(body_index)):
            props = ProximityProperties()
            AddRigidHydroelasticProperties(params.hydroelastic_resolution_hint_m, props)
            AddContactMaterial(
                params.hunt_crossley_dissipation_s_per_m,
                None,
                CoulombFriction(
                    params.friction_coefficient, params.friction_coefficient
                ),
                props,
            )
            scene_graph.AssignRole(
                plant.get_source_id(), gid, props, RoleAssign.kReplace
            )
            ids.append(gid)
    return ids


def MakeStation(
    params: StationParams,
    *,
    phantom: Phantom,
    meshcat=None,
    initial_q=None,
) -> Diagram:
    """Builds the simulated rig as a Diagram named ``"station"``.

    Args:
        params: the rig (:class:`StationParams`).
        phantom: the tissue map (its surface gives the contact mesh, its
            kappa, lambda, beta the Hunt-Crossley force).
        meshcat: optional Meshcat for visualization.
        initial_q: optional default joint angles (6,), rad (e.g. from
            :func:`initial_q_for_tip`); default all zero.

    Input ports:
        ur3e.position_command (6): commanded joint angles, rad.
        phantom.lift (1): phantom z offset command, m (servoed stiffly).
    Output ports:
        ur3e.state (12): q (rad), v (rad/s).
        ft_sensor.force_W (3): tared, noisy (and, with sensor_lag_samples,
            delayed) sensor force in W, N
            (negative z = the probe pressing down into the body).
        ft_sensor.wrench_S (6): the same reading ``[tau; f]`` in the sensor
            frame S (N m, N).
        probe.position (3): p_WP of the tip, m.  probe.velocity (3): m/s.
        tissue.force_W (3): true Hunt-Crossley force on the tip, N (+z up).
        tissue.penetration (1): eps = surface - tip height, m.
        tissue.surface_z (1): surface height under the tip in W, m.
        phantom.z_offset (1): the phantom's current lift, m.
        plant.body_poses, plant.contact_results: for logging/visualization.
    """
    if not isinstance(params, StationParams):
        raise VicDrakeError(
            f"params must be a StationParams, got {type(params).__name__}"
        )
    if not isinstance(phantom, Phantom):
        raise VicDrakeError(
            f"phantom must be a vic_drake.tissue.Phantom, got {type(phantom).__name__}"
        )
    builder = DiagramBuilder()
    config = MultibodyPlantConfig(
        time_step=params.time_step_s,
        discrete_contact_approximation=params.contact_approximation,
        contact_model="hydroelastic_with_fallback",
    )
    plant, scene_graph = AddMultibodyPlant(config, builder)
    plant.mutable_gravity_field().set_gravity_vector([0, 0, -params.gravity_m_per_s2])
    ur3e = AddUr3e(plant)
    arm = AddTool(plant, ur3e, params)
    phantom_model, phantom_body, phantom_geometry = _add_phantom(plant, params, phantom)
    link_geometries = _make_links_hydroelastic(plant, scene_graph, ur3e, params)
    tool_geometries = list(arm.tool_geometries.values())
    indenter_geometries = [
        arm.tool_geometries["indenter_cone"],
        arm.tool_geometries["indenter_tip"],
    ]
    filters = CollisionFilterDeclaration()
    # No self collision of the arm and tool (the URDF's primitives overlap).
    filters.ExcludeWithin(GeometrySet(link_geometries + tool_geometries))
    # The indenter's contact with tissue is the Hunt-Crossley element only.
    filters.ExcludeBetween(
        GeometrySet(indenter_geometries), GeometrySet([phantom_geometry])
    )
    if not params.robot_contact:
        filters.ExcludeBetween(
            GeometrySet(link_geometries + tool_geometries),
            GeometrySet([phantom_geometry]),
        )
    scene_graph.collision_filter_manager().Apply(filters)
    plant.Finalize()
    _set_pd_gains(
        plant,
        UR3E_JOINTS,
        ur3e,
        params.joint_kp_Nm_per_rad,
        params.joint_kd_Nms_per_rad,
    )
    if initial_q is not None:
        q0 = np.asarray(initial_q, float)
        if q0.shape != (6,) or not np.all(np.isfinite(q0)):
            raise VicDrakeError(
                f"initial_q must be 6 finite joint angles (rad), got {initial_q!r}"
            )
        plant.SetDefaultPositions(ur3e, q0)

    # Position servo: the command, smoothed as the UR's servoj does, is the
    # desired state of the PD actuators.
    q_default = plant.GetDefaultPositions(ur3e)
    ur_measured = builder.AddNamedSystem("ur3e_state_demux", Demultiplexer([6, 6]))
    servo_inputs = builder.AddNamedSystem("ur3e_servo_inputs", Multiplexer([6, 6]))
    ur_filter = builder.AddNamedSystem(
        "ur3e_servo_filter",
        LinearSystem(
            *joint_servo_system_matrices(
                6,
                params.command_period_s,
                params.servo_time_constant_s,
                params.servo_integral_time_s,
            ),
            params.command_period_s,
        ),
    )
    ur_filter.configure_default_state(joint_servo_rest_state(q_default))
    builder.Connect(plant.get_state_output_port(ur3e), ur_measured.get_input_port())
    builder.Connect(ur_measured.get_output_port(0), servo_inputs.get_input_port(1))
    builder.Connect(servo_inputs.get_output_port(), ur_filter.get_input_port())
    builder.Connect(
        ur_filter.get_output_port(), plant.get_desired_state_input_port(ur3e)
    )
    builder.ExportInput(servo_inputs.get_input_port(0), "ur3e.position_command")
    lift_interp = builder.AddNamedSystem(
        "phantom_lift_interpolator",
        StateInterpolatorWithDiscreteDerivative(1, params.command_period_s, True),
    )
    builder.Connect(
        lift_interp.get_output_port(), plant.get_desired_state_input_port(phantom_model)
    )
    builder.ExportInput(lift_interp.get_input_port(), "phantom.lift")

    # Gravity feed-forward (the UR controller's own gravity compensation, and
    # the phantom's weight held by its lift).
    gravity = builder.AddNamedSystem(
        "gravity_compensation",
        InverseDynamics(
            plant, InverseDynamics.InverseDynamicsMode.kGravityCompensation
        ),
    )
    builder.Connect(
        plant.get_state_output_port(), gravity.get_input_port_estimated_state()
    )
    nv = plant.num_velocities()
    for model, n in ((ur3e, 6), (phantom_model, 1)):
        select = np.zeros((n, nv))
        for row, a in enumerate(plant.GetJointActuatorIndices(model)):
            select[row, plant.get_joint_actuator(a).joint().velocity_start()] = 1.0
        gain = builder.AddNamedSystem(
            f"{plant.GetModelInstanceName(model)}_gravity_ff", MatrixGain(select)
        )
        builder.Connect(
            gravity.get_output_port_generalized_force(), gain.get_input_port()
        )
        builder.Connect(gain.get_output_port(), plant.get_actuation_input_port(model))

    # Hunt-Crossley tissue force on the tip.
    p_IP = np.array([0.0, 0.0, params.indenter_length_m])
    tissue = builder.AddNamedSystem(
        "tissue_force",
        TissueForceElement(
            phantom,
            indenter_body_index=arm.indenter_body.index(),
            p_BT=p_IP,
            phantom_body_index=phantom_body.index(),
            lookup_resolution_m=params.tissue_lookup_resolution_m,
            friction_coefficient=params.tissue_friction_coefficient,
            slip_speed_m_per_s=params.tissue_slip_speed_m_per_s,
            along_normal=params.tissue_force_along_normal,
        ),
    )
    builder.Connect(
        plant.get_body_poses_output_port(), tissue.get_body_poses_input_port()
    )
    builder.Connect(
        plant.get_body_spatial_velocities_output_port(),
        tissue.get_body_spatial_velocities_input_port(),
    )
    builder.Connect(
        tissue.get_spatial_forces_output_port(),
        plant.get_applied_spatial_force_input_port(),
    )
    builder.ExportOutput(tissue.get_force_output_port(), "tissue.force_W")
    builder.ExportOutput(tissue.get_penetration_output_port(), "tissue.penetration")
    builder.ExportOutput(tissue.get_surface_z_output_port(), "tissue.surface_z")

    # F/T sensor from the weld's reaction.
    m_ws, m_i = params.ft_wrench_mass_kg, params.indenter_mass_kg
    p_SScm = (
        m_ws * np.array([0, 0, -params.ft_wrench_offset_m / 4])
        + m_i * np.array([0, 0, 0.4 * params.indenter_length_m])
    ) / (m_ws + m_i)
    noise_std = np.concatenate(
        [np.full(3, params.sensor_torque_noise_std_Nm), params.sensor_noise_std_N]
    )
    sensor = builder.AddNamedSystem(
        "ft_sensor",
        ForceTorqueSensor(
            weld_joint_index=arm.sensor_weld.index(),
            child_body_index=arm.sensor_body.index(),
            X_CS=RigidTransform(),
            distal_mass_kg=params.distal_mass_kg,
            p_SScm=p_SScm,
            period_s=params.sensor_period_s,
            lag_samples=int(params.sensor_lag_samples),
            noise_std=noise_std,
            bias=np.concatenate([np.zeros(3), params.sensor_bias_N]),
            gravity_W=[0, 0, -params.gravity_m_per_s2],
        ),
    )
    builder.Connect(
        plant.get_reaction_forces_output_port(), sensor.get_reaction_forces_input_port()
    )
    builder.Connect(
        plant.get_body_poses_output_port(), sensor.get_body_poses_input_port()
    )
    if np.any(noise_std > 0):
        noise = builder.AddNamedSystem(
            "ft_sensor_noise",
            RandomSource(RandomDistribution.kGaussian, 6, params.sensor_period_s),
        )
        builder.Connect(noise.get_output_port(), sensor.get_noise_input_port())
    builder.ExportOutput(sensor.get_force_output_port(), "ft_sensor.force_W")
    builder.ExportOutput(sensor.get_wrench_output_port(), "ft_sensor.wrench_S")

    # The tip's kinematics come from the tissue element, which computes them
    # every step anyway.
    builder.ExportOutput(tissue.get_tip_position_output_port(), "probe.position")
    builder.ExportOutput(tissue.get_tip_velocity_output_port(), "probe.velocity")

    builder.ExportOutput(plant.get_state_output_port(ur3e), "ur3e.state")
    demux = builder.AddNamedSystem("phantom_state_demux", Demultiplexer(2, 1))
    builder.Connect(plant.get_state_output_port(phantom_model), demux.get_input_port())
    builder.ExportOutput(demux.get_output_port(0), "phantom.z_offset")
    builder.ExportOutput(plant.get_body_poses_output_port(), "plant.body_poses")
    builder.ExportOutput(
        plant.get_contact_results_output_port(), "plant.contact_results"
    )

    if meshcat is not None:
        from pydrake.visualization import AddDefaultVisualization

        AddDefaultVisualization(builder, meshcat=meshcat)

    diagram = builder.Build()
    diagram.set_name("station")
    return diagram


def station_plant(station: Diagram) -> MultibodyPlant:
    """The station's MultibodyPlant (subsystem "plant")."""
    return station.GetSubsystemByName("plant")


def set_station_state(
    station: Diagram, station_context, q, *, phantom_lift_m: float = 0.0
):
    """Sets the arm at rest at q (6,) and the phantom at a lift, in a station context."""
    plant = station_plant(station)
    plant_context = station.GetMutableSubsystemContext(plant, station_context)
    ur3e = plant.GetModelInstanceByName("ur3e")
    plant.SetPositions(plant_context, ur3e, np.asarray(q, float))
    plant.SetVelocities(plant_context, ur3e, np.zeros(6))
    servo = station.GetSubsystemByName("ur3e_servo_filter")
    station.GetMutableSubsystemContext(servo, station_context).SetDiscreteState(
        joint_servo_rest_state(q)
    )
    phantom = plant.GetModelInstanceByName("phantom")
    plant.SetPositions(plant_context, phantom, [phantom_lift_m])
    plant.SetVelocities(plant_context, phantom, [0.0])


__all__ = [
    "DEFAULT_Q_SEED",
    "FALLBACK_Q_SEEDS",
    "UR3E_JOINTS",
    "AddTool",
    "AddUr3e",
    "ArmHandles",
    "MakeStation",
    "MakeUr3ePlant",
    "StationParams",
    "initial_q_for_tip",
    "joint_filter_step",
    "joint_servo_rest_state",
    "joint_servo_system_matrices",
    "probe_down_rotation",
    "probe_pose",
    "set_station_state",
    "solve_tip_ik",
    "station_plant",
]
