"""The rig's C++ core: plant, arm, tool, phantom, joint servo, lift, gravity.

:func:`AddRig` adds to a builder everything of the station that Drake
computes in C++ (no Python LeafSystem): the MultibodyPlant with the UR3e,
its tool and the lifted phantom, the contact filters, the joint position
servo, the phantom's lift servo and the gravity feed-forward.
:func:`vic_drake.station.MakeStation` adds the Python tissue force element
and F/T sensor on top; ``benchmarks/bench_scan.py`` simulates the rig alone
as the speed ceiling of a scan.

With ``phantom_lateral=True`` the phantom rides on two carriages, on
prismatic joints along W x (``phantom_x``) and y (``phantom_y``), under its
lift, each servoed with the lift's gains; without it the plant is the
7-position plant of every other scenario.
"""

from typing import NamedTuple

import numpy as np
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    CollisionFilterDeclaration,
    GeometrySet,
    Mesh,
    ProximityProperties,
    RoleAssign,
)
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlant, CoulombFriction
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    PdControllerGains,
    PrismaticJoint,
    SpatialInertia,
    UnitInertia,
)
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.primitives import (
    Demultiplexer,
    LinearSystem,
    MatrixGain,
    Multiplexer,
    StateInterpolatorWithDiscreteDerivative,
)

from vic_drake.errors import VicDrakeError
from vic_drake.models.phantom_mesh import phantom_mesh_paths
from vic_drake.models.ur3e import UR3E_JOINTS, AddTool, AddUr3e
from vic_drake.station.params import StationParams
from vic_drake.station.servo import (
    _set_pd_gains,
    joint_servo_rest_state,
    joint_servo_system_matrices,
)
from vic_drake.tissue import Phantom


class Rig(NamedTuple):
    """What :func:`AddRig` added.

    Attributes:
        plant, scene_graph: the MultibodyPlant and its SceneGraph.
        ur3e: the arm's model instance; arm: its tool handles
            (:class:`vic_drake.models.ur3e.ArmHandles`).
        phantom_model, phantom_body: the phantom's model instance and body.
        position_command: input port (6) of the commanded joint angles, rad.
        phantom_lift: input port (1) of the phantom's lift command, m.
        phantom_lateral: input port (2) of the phantom's x, y command, m
            (None without lateral joints).
    """

    plant: object
    scene_graph: object
    ur3e: object
    arm: object
    phantom_model: object
    phantom_body: object
    position_command: object
    phantom_lift: object
    phantom_lateral: object = None


#: Mass of each lateral carriage under the phantom, kg (a fictitious stage:
#: small beside the phantom, but a body on a joint needs mass).
CARRIAGE_MASS_KG = 0.05


def _add_servo(plant, joint, params: StationParams) -> None:
    """A PD actuator with the phantom lift's gains on a prismatic joint."""
    actuator = plant.AddJointActuator(f"{joint.name()}_actuator", joint)
    actuator.set_controller_gains(
        PdControllerGains(p=params.phantom_kp_N_per_m, d=params.phantom_kd_Ns_per_m)
    )


def _add_carriages(plant, model, base_frame):
    """The lateral stage: an x carriage on ``base_frame``, a y carriage on it.

    Returns the y carriage's frame (the lift's parent) and the two joints.
    """
    inertia = SpatialInertia(
        CARRIAGE_MASS_KG, np.zeros(3), UnitInertia.SolidSphere(0.01)
    )
    joints = []
    parent = base_frame
    for axis, name in (([1, 0, 0], "x"), ([0, 1, 0], "y")):
        carriage = plant.AddRigidBody(f"phantom_carriage_{name}", model, inertia)
        joints.append(
            plant.AddJoint(
                PrismaticJoint(f"phantom_{name}", parent, carriage.body_frame(), axis)
            )
        )
        parent = carriage.body_frame()
    return parent, joints


def _add_phantom(plant, params: StationParams, phantom: Phantom, lateral: bool):
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
    lift_parent, lateral_joints = frame_on_world, []
    if lateral:
        lift_parent, lateral_joints = _add_carriages(plant, model, frame_on_world)
    joint = plant.AddJoint(
        PrismaticJoint("phantom_lift", lift_parent, body.body_frame(), [0, 0, 1])
    )
    # Actuators [lift, x, y]: the order of the phantom's servo commands.
    for servoed in (joint, *lateral_joints):
        _add_servo(plant, servoed, params)
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


def AddRig(
    builder,
    params: StationParams,
    phantom: Phantom,
    *,
    initial_q=None,
    phantom_lateral: bool = False,
) -> Rig:
    """Adds the rig's C++ systems to ``builder`` (see the module docstring).

    Args:
        builder: a DiagramBuilder.
        params: the rig (validated here).
        phantom: the tissue map (its surface gives the contact mesh).
        initial_q: optional default joint angles (6,), rad.
        phantom_lateral: give the phantom x and y joints (lateral motion);
            False: the lift only.

    Returns:
        :class:`Rig`; its input ports are left for the caller to connect
        or export.
    """
    params.validate()
    if not isinstance(phantom_lateral, bool):
        raise VicDrakeError(
            f"phantom_lateral must be true or false; got {phantom_lateral!r}"
        )
    plant, scene_graph = AddMultibodyPlant(params.plant, builder)
    plant.mutable_gravity_field().set_gravity_vector([0, 0, -params.gravity_m_per_s2])
    ur3e = AddUr3e(plant)
    arm = AddTool(plant, ur3e, params)
    phantom_model, phantom_body, phantom_geometry = _add_phantom(
        plant, params, phantom, phantom_lateral
    )
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
    # The phantom's servo: its commands [lift(, x, y)] in actuator order.
    n_phantom = plant.num_actuators(phantom_model)
    lift_interp = builder.AddNamedSystem(
        "phantom_lift_interpolator",
        StateInterpolatorWithDiscreteDerivative(
            n_phantom, params.command_period_s, True
        ),
    )
    builder.Connect(
        lift_interp.get_output_port(), plant.get_desired_state_input_port(phantom_model)
    )
    lift_port, lateral_port = lift_interp.get_input_port(), None
    if phantom_lateral:
        commands = builder.AddNamedSystem("phantom_command_mux", Multiplexer([1, 2]))
        builder.Connect(commands.get_output_port(), lift_interp.get_input_port())
        lift_port, lateral_port = commands.get_input_port(0), commands.get_input_port(1)

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
    for model, n in ((ur3e, 6), (phantom_model, n_phantom)):
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

    return Rig(
        plant,
        scene_graph,
        ur3e,
        arm,
        phantom_model,
        phantom_body,
        servo_inputs.get_input_port(0),
        lift_port,
        lateral_port,
    )


__all__ = ["AddRig", "Rig"]
