"""MakeStation: the simulated rig as a Diagram (UR3e, F/T sensor, indenter, phantom).

The arm and tool are :mod:`vic_drake.models.ur3e`; the phantom (body Ph) is
the chest on a prismatic z joint (``phantom_lift``) at ``phantom_offset_m``
(with ``phantom_lateral=True``, on x and y joints too); its frame carries
the map's coordinates, so with zero lift and offset the map is in W.

Forces: the tissue's push on the indenter is the Hunt-Crossley element of
:mod:`vic_drake.systems.tissue_force` (Drake contact between the indenter
and the phantom is filtered out). Robot links and the sensor housing have
coarse rigid hydroelastic geometry that meets the phantom's compliant
hydroelastic volume mesh (:mod:`vic_drake.models.phantom_mesh`): a safety
contact, not the measured force.

The arm is position controlled through the servo front end of
:mod:`vic_drake.station.servo`, with the arm's gravity torques as
feed-forward (the UR controller compensates gravity itself). Effort limits
are the URDF's (56, 56, 28, 12, 12, 12 N m).

Notes for users: the plant's output ports are sampled (Drake's default for
discrete plants), so ``plant.contact_results`` and the reaction forces
behind the F/T reading describe the last plant step -- take one step after
setting a state by hand. The sensor noise comes from a ``RandomSource``
whose seed lives in the Context (deterministic by default; call
``diagram.SetRandomContext(context, RandomGenerator(seed))`` for another
draw). Speed (``benchmarks/bench_station.py``, ``benchmarks/bench_scan.py``):
the plant steps with the command, so each Python LeafSystem (tissue force
and tip kinematics, sensor, servo filter; in a scan the controller and FDCC)
runs once per step.
"""

import numpy as np
from pydrake.common import RandomDistribution
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import Demultiplexer, MatrixGain, RandomSource

from vic_drake.errors import VicDrakeError
from vic_drake.station.params import StationParams
from vic_drake.station.rig import AddRig
from vic_drake.station.servo import joint_servo_rest_state
from vic_drake.systems.ft_sensor import ForceTorqueSensor
from vic_drake.systems.tissue_force import TissueForceElement
from vic_drake.tissue import Phantom


def MakeStation(
    params: StationParams,
    *,
    phantom: Phantom,
    meshcat=None,
    initial_q=None,
    phantom_lateral: bool = False,
) -> Diagram:
    """Builds the simulated rig as a Diagram named ``"station"``.

    Args:
        params: the rig (:class:`StationParams`).
        phantom: the tissue map (its surface gives the contact mesh, its
            kappa, lambda, beta the Hunt-Crossley force).
        meshcat: optional Meshcat for visualization.
        initial_q: optional default joint angles (6,), rad (e.g. from
            :func:`initial_q_for_tip`); default all zero.
        phantom_lateral: the phantom also moves in x and y (two more servoed
            prismatic joints, and the ``phantom.lateral`` ports); False:
            the lift only.

    Input ports:
        ur3e.position_command (6): commanded joint angles, rad.
        phantom.lift (1): phantom z offset command, m (servoed stiffly).
        phantom.lateral (2): phantom x, y offset command, m (servoed as the
            lift; only with ``phantom_lateral``).
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
        tissue.sample (17): the tip and the tissue after the last tick, as
            stored by the tissue element (its ``SAMPLE_FIELDS``; what the
            scan logs).
        phantom.z_offset (1): the phantom's current lift, m.
        phantom.lateral_offset (2): its current x, y offset, m (only with
            ``phantom_lateral``).
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
    rig = AddRig(
        builder, params, phantom, initial_q=initial_q, phantom_lateral=phantom_lateral
    )
    plant, ur3e, arm = rig.plant, rig.ur3e, rig.arm
    phantom_model, phantom_body = rig.phantom_model, rig.phantom_body
    builder.ExportInput(rig.position_command, "ur3e.position_command")
    builder.ExportInput(rig.phantom_lift, "phantom.lift")
    if rig.phantom_lateral is not None:
        builder.ExportInput(rig.phantom_lateral, "phantom.lateral")

    # Hunt-Crossley tissue force on the tip (relaxing unless tissue_law="hc").
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
            relaxation=params.relaxation,
            update_period_s=params.plant.time_step,
            plant=plant,
        ),
    )
    # The element and the sensor read one or two bodies: from the plant's
    # state vector, not the lists of every body's pose and velocity.
    builder.Connect(plant.get_state_output_port(), tissue.get_plant_state_input_port())
    builder.Connect(
        tissue.get_spatial_forces_output_port(),
        plant.get_applied_spatial_force_input_port(),
    )
    builder.ExportOutput(tissue.get_force_output_port(), "tissue.force_W")
    builder.ExportOutput(tissue.get_penetration_output_port(), "tissue.penetration")
    builder.ExportOutput(tissue.get_surface_z_output_port(), "tissue.surface_z")
    builder.ExportOutput(tissue.get_sample_output_port(), "tissue.sample")

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
            plant=plant,
        ),
    )
    builder.Connect(
        plant.get_reaction_forces_output_port(), sensor.get_reaction_forces_input_port()
    )
    builder.Connect(plant.get_state_output_port(), sensor.get_plant_state_input_port())
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
    if rig.phantom_lateral is None:
        demux = builder.AddNamedSystem("phantom_state_demux", Demultiplexer(2, 1))
        builder.Connect(
            plant.get_state_output_port(phantom_model), demux.get_input_port()
        )
        builder.ExportOutput(demux.get_output_port(0), "phantom.z_offset")
    else:
        _export_phantom_offsets(builder, plant, phantom_model)
    builder.ExportOutput(plant.get_body_poses_output_port(), "plant.body_poses")
    builder.ExportOutput(
        plant.get_contact_results_output_port(), "plant.contact_results"
    )

    if meshcat is not None:
        # Local import: the visualization module is needed only with a Meshcat.
        from pydrake.visualization import AddDefaultVisualization

        AddDefaultVisualization(builder, meshcat=meshcat)

    diagram = builder.Build()
    diagram.set_name("station")
    return diagram


def _export_phantom_offsets(builder, plant, phantom_model) -> None:
    """Exports the lift and the x, y joints' positions of a laterally moving phantom."""
    # The model's state is [q; v] in the plant's order of its positions.
    q_of_model = list(
        plant.GetPositionsFromArray(
            phantom_model, np.arange(plant.num_positions(), dtype=float)
        )
    )
    n = 2 * len(q_of_model)
    for names, port in (
        (("phantom_lift",), "phantom.z_offset"),
        (("phantom_x", "phantom_y"), "phantom.lateral_offset"),
    ):
        select = np.zeros((len(names), n))
        for row, name in enumerate(names):
            start = plant.GetJointByName(name, phantom_model).position_start()
            select[row, q_of_model.index(float(start))] = 1.0
        gain = builder.AddNamedSystem(f"{port}_select", MatrixGain(select))
        builder.Connect(
            plant.get_state_output_port(phantom_model), gain.get_input_port()
        )
        builder.ExportOutput(gain.get_output_port(), port)


def station_plant(station: Diagram) -> MultibodyPlant:
    """The station's MultibodyPlant (subsystem "plant")."""
    return station.GetSubsystemByName("plant")


def set_station_state(station: Diagram, station_context, q, *, phantom_command=(0.0,)):
    """Sets the arm at rest at q (6,) and the phantom at rest, in a station context.

    ``phantom_command``: where the phantom's joints are, m, in its servo's
    command order: [lift] or [lift, x, y] (lateral joints not given stay
    at zero).
    """
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
    n = plant.num_positions(phantom)  # 1, or 3 with the lateral joints
    plant.SetPositions(plant_context, phantom, np.zeros(n))
    plant.SetVelocities(plant_context, phantom, np.zeros(n))
    for name, value in zip(("phantom_lift", "phantom_x", "phantom_y"), phantom_command):
        plant.GetJointByName(name, phantom).set_translation(plant_context, value)


__all__ = ["MakeStation", "set_station_state", "station_plant"]
