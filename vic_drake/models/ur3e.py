"""The UR3e arm and its tool (BOTA SensONE F/T sensor, indenter, probe frame).

Frames (monogram notation):

- ``W`` -- the world frame, identical to the rig's UR ``base_link`` frame
  (ROS/REP-103 convention: a half turn about z from UR's own ``base``
  frame). The airo-models UR3e URDF's root link *is* ``base_link``, and it
  is welded at W's origin, so the logged positions of the real rig (and the
  phantom map) are W coordinates here.
- ``wrist_3_link`` -- the UR's last link (its frame coincides with ``tool0``,
  z out of the flange).
- ``ft_sensor_mount`` (body M) -- the sensor's mounting side, welded to the
  flange at ``wrist_3 * Rz(-pi/2)`` (the rig's ``ft_frame`` = wrist_3 turned
  pi about x, then the mounting turned rpy (pi, 0, pi/2): together a
  quarter turn about z, z still out of the flange).
- ``ft_sensor_wrench`` (body S, frame S) -- the sensor's wrench side; S is
  the sensor's wrench frame, ``ft_wrench_offset_m`` along M's z. M and S
  are joined by the weld ``ft_sensor_weld``, whose reaction force is the
  F/T reading (:mod:`vic_drake.systems.ft_sensor`).
- ``indenter`` (body I, frame = S) -- the 3D-printed rigid cone with a
  spherical tip, welded to S.
- ``probe`` (frame P on I) -- the indenter tip, ``indenter_length_m``
  further along S's z, the lowest point of the tip sphere, with S's
  orientation. The real controller's pose target keeps P pointing straight
  down: ``R_WP = Rx(pi)`` (quaternion x = 1, w = 0), see
  :func:`probe_down_rotation`.

The tool's dimensions, masses and contact properties come from a
:class:`vic_drake.station.StationParams` (any object with its fields).
:func:`MakeFdccModel` builds FDCC's internal model of the same arm
(:mod:`vic_drake.control.fdcc`).
"""

from dataclasses import dataclass, field

import numpy as np
from airo_models import get_urdf_path
from pydrake.common.eigen_geometry import Quaternion
from pydrake.geometry import (
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    Cylinder,
    ProximityProperties,
    Sphere,
)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    ModelInstanceIndex,
    RotationalInertia,
    SpatialInertia,
    UnitInertia,
    WeldJoint,
)

from vic_drake.control.fdcc import FdccModel, FdccParams

#: The UR3e's six joints, in the order of every q vector in vic_drake.
UR3E_JOINTS = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)


def probe_down_rotation() -> RotationMatrix:
    """R_WP of the real controller's target: quaternion (w, x, y, z) = (0, 1, 0, 0)."""
    return RotationMatrix(Quaternion(0.0, 1.0, 0.0, 0.0))


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
    params,
    *,
    with_geometry: bool = True,
) -> ArmHandles:
    """Adds the F/T sensor (two bodies and their weld), indenter and probe frame.

    Masses: mounting side ``ft_mount_mass_kg``, wrench side
    ``ft_wrench_mass_kg`` (SensONE, 0.149 / 0.081 kg) and the indenter
    ``indenter_mass_kg``. The indenter is modelled as a cylinder of the tip
    radius down to the tip sphere's centre plus the tip sphere (a simplified
    7 cm cone).

    Args:
        plant: the plant (not finalized) holding ``ur3e``.
        ur3e: the arm's model instance (:func:`AddUr3e`).
        params: the tool's geometry, masses and contact properties
            (:class:`vic_drake.station.StationParams`).
        with_geometry: register visual and collision geometry when the plant
            has a SceneGraph.
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
    params, *, time_step: float = 0.0
) -> tuple[MultibodyPlant, ArmHandles]:
    """A finalized plant of the UR3e with the tool and ``probe`` frame only.

    For inverse kinematics and analysis (no phantom, no scene graph).

    Args:
        params: the tool's geometry and masses
            (:class:`vic_drake.station.StationParams`).
        time_step: the plant's discrete step, s (0: continuous).
    """
    plant = MultibodyPlant(time_step)
    ur3e = AddUr3e(plant)
    handles = AddTool(plant, ur3e, params, with_geometry=False)
    plant.Finalize()
    return plant, handles


def MakeFdccModel(params: FdccParams, station_params) -> FdccModel:
    """FDCC's internal model of the UR3e (FZI's generic model), ready to step.

    The arm's kinematics with a body ``fdcc_end_effector`` at the probe frame
    (mass ``params.end_effector_mass_kg``, rotational inertia
    ``params.end_effector_inertia_kg_m2``); :class:`FdccModel` gives the arm's
    moving links their light inertias.

    Args:
        params: the FDCC settings.
        station_params: the tool geometry that places the probe
            (:class:`vic_drake.station.StationParams`: ``X_W3M``, ``p_MP``).
    """
    plant = MultibodyPlant(0.0)
    ur3e = AddUr3e(plant)
    X_3P = station_params.X_W3M @ RigidTransform(station_params.p_MP)
    ee = plant.AddRigidBody(
        "fdcc_end_effector",
        ur3e,
        SpatialInertia(
            params.end_effector_mass_kg,
            np.zeros(3),
            UnitInertia.TriaxiallySymmetric(
                params.end_effector_inertia_kg_m2 / params.end_effector_mass_kg
            ),
        ),
    )
    plant.WeldFrames(plant.GetFrameByName("wrist_3_link", ur3e), ee.body_frame(), X_3P)
    plant.Finalize()
    return FdccModel(params, plant, ee.body_frame())


__all__ = [
    "UR3E_JOINTS",
    "AddTool",
    "AddUr3e",
    "ArmHandles",
    "MakeFdccModel",
    "MakeUr3ePlant",
    "probe_down_rotation",
]
