"""The closed-loop scan diagram of a scenario, and its initial state.

:func:`MakeScanDiagram` wires the station (UR3e, F/T sensor, probe,
phantom), the FDCC compliance stage, the variable impedance controller, the
target and phantom-lift sources, and the log of the signal groups of
:data:`vic_drake.experiments.scan_logs.LOG_GROUPS` and
:data:`vic_drake.experiments.rig_log.RIG_GROUPS` (one VectorLogSink behind one
C++ Multiplexer, :func:`vic_drake.experiments.scan_logs.AddScanLogs`).

Signal flow (all vectors in the base frame W)::

    target ──► controller ◄── probe.position / probe.velocity / ft_sensor.force_W
                 │ stiffness, target_force
                 ▼
    target ──► fdcc ◄── ur3e.state (q), ft_sensor.force_W  (one vector: "fdcc_inputs")
                 │ position_command
                 ▼
    lift ────► station
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource, Demultiplexer

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.rig_log import rig_log_ports
from vic_drake.experiments.scan_logs import AddScanLogs, log_group_ports
from vic_drake.experiments.scan_variations import (
    add_sensor_faults,
    controller_map,
    patient_motion_source,
    patient_phantom_of,
)
from vic_drake.scenario import Scenario
from vic_drake.station import (
    MakeStation,
    MakeUr3ePlant,
    initial_q_for_tip,
    set_station_state,
)
from vic_drake.systems.controller import MakeVariableImpedanceController
from vic_drake.systems.fdcc import AddFdccInputs, FdccController
from vic_drake.systems.trajectory import PhantomLiftSource, TargetTrajectorySource
from vic_drake.tissue.phantom import GridPhantom, load_phantom


def load_scenario_phantom(scenario: Scenario, *, data_dir=None):
    """The phantom of a scenario (the measured map needs the data folder)."""
    patient = patient_phantom_of(scenario)
    if patient is not None:
        return patient
    return load_phantom(
        scenario.phantom.kind, data_dir=data_dir, lookup=scenario.phantom.lookup
    )


def _controller_phantom(scenario: Scenario, phantom):
    """The map the controller reads: the tissue's map with the controller's lookup.

    A separate GridPhantom (sharing the arrays), not a copy: a phantom caches
    its fast point lookup, and a copy would inherit the tissue's.
    """
    lookup = scenario.phantom.controller_lookup
    if isinstance(phantom, GridPhantom) and phantom.lookup != lookup:
        return GridPhantom(
            x_m=phantom.x_m,
            y_m=phantom.y_m,
            z_m=phantom.surface_m - phantom.surface_offset_m,
            kappa=phantom.kappa_grid,
            lam=phantom.lam_grid,
            beta=phantom.beta,
            surface_offset_m=phantom.surface_offset_m,
            lookup=lookup,
            name=f"{phantom.name} ({lookup})",
        )
    return phantom


class CommandedTipKinematics(LeafSystem):
    """Probe tip position and velocity of a joint command (forward kinematics).

    FZI's compliance controller on a position interface closes its loop on
    its own joint command, not on the measured joints; with
    ``Scenario.controller_feedback = "command"`` the variable impedance
    controller reads the tip through this system likewise.

    Input ports:
        q: (6,) joint command, rad.
    Output ports:
        position: (3,) p_WP of FK(q), m.
        velocity: (3,) finite difference over the last period, m/s.

    State: the tip position at the last tick (3,), updated every period_s.
    """

    def __init__(self, station_params, *, period_s: float, q0):
        super().__init__()
        self._plant, handles = MakeUr3ePlant(station_params)
        self._frame = handles.probe_frame
        self._scratch = self._plant.CreateDefaultContext()  # FK scratch, no state.
        self._period_s = float(period_s)
        self._q_port = self.DeclareVectorInputPort("q", 6)
        self._last = self.DeclareDiscreteState(self._fk(q0))
        self.DeclarePeriodicDiscreteUpdateEvent(self._period_s, 0.0, self._update)
        self.DeclareVectorOutputPort("position", 3, self._calc_position)
        self.DeclareVectorOutputPort("velocity", 3, self._calc_velocity)

    def _fk(self, q) -> np.ndarray:
        self._plant.SetPositions(self._scratch, np.asarray(q, float))
        return self._frame.CalcPoseInWorld(self._scratch).translation().copy()

    def _update(self, context, discrete_state):
        discrete_state.set_value(self._last, self._fk(self._q_port.Eval(context)))

    def _calc_position(self, context, output):
        output.SetFromVector(self._fk(self._q_port.Eval(context)))

    def _calc_velocity(self, context, output):
        p = self._fk(self._q_port.Eval(context))
        last = context.get_discrete_state(self._last).get_value()
        output.SetFromVector((p - last) / self._period_s)


def MakeScanDiagram(
    scenario: Scenario,
    *,
    phantom=None,
    meshcat=None,
    data_dir=None,
    controller_phantom=None,
):
    """Builds the closed-loop scan diagram of a scenario.

    Args:
        scenario: the run's configuration.
        phantom: the tissue (default: the scenario's phantom kind, loaded).
        controller_phantom: the map the controller reads, before the
            scenario's map errors (default: ``phantom``); compare-real's
            surface profile raises the tissue and not the controller's map.
        meshcat: optional Meshcat for visualisation.
        data_dir: data folder for the measured map (default: vic_drake.paths).

    Returns:
        (diagram, logs): the Diagram named "scan" and its
        :class:`~vic_drake.experiments.scan_logs.ScanLogs`, logging every
        ``scenario.logging.period_s`` the groups of :data:`LOG_GROUPS` (and
        :data:`LATERAL_LOG_GROUP` when the phantom moves laterally) and of
        :data:`vic_drake.experiments.rig_log.RIG_GROUPS`.
    """
    if not isinstance(scenario, Scenario):
        raise VicDrakeError(
            f"MakeScanDiagram needs a Scenario; got {type(scenario).__name__}"
        )
    scenario.validate()  # Fields set in code since it was made are checked too.
    if phantom is None:
        phantom = load_scenario_phantom(scenario, data_dir=data_dir)
    q0 = initial_joint_positions(scenario)
    builder = DiagramBuilder()
    # Lateral joints under the phantom only when the scenario moves it
    # sideways: every other scenario builds the 7-position plant.
    lateral = scenario.variations.motion.lateral_active
    station = builder.AddNamedSystem(
        "station",
        MakeStation(
            scenario.station,
            phantom=phantom,
            meshcat=meshcat,
            initial_q=q0,
            phantom_lateral=lateral,
        ),
    )
    controller = builder.AddNamedSystem(
        "variable_impedance_controller",
        MakeVariableImpedanceController(
            scenario.controller,
            phantom=controller_map(
                scenario,
                _controller_phantom(
                    scenario,
                    phantom if controller_phantom is None else controller_phantom,
                ),
            ),
            stiffness_source=scenario.stiffness_source,
            estimator=scenario.online_estimator,
            online_surface=scenario.online_surface,
        ),
    )
    fdcc = builder.AddNamedSystem(
        "fdcc",
        FdccController(
            scenario.fdcc,
            station_params=scenario.station,
            initial_q=q0,
            watchdog=scenario.watchdog,
        ),
    )
    target = builder.AddNamedSystem(
        "target", TargetTrajectorySource(scenario.trajectory)
    )
    # A nominal run's phantom stays put: a constant (C++) source, evaluated
    # for free every tick.
    motion = patient_motion_source(scenario)
    lift = builder.AddNamedSystem(
        "phantom_lift",
        motion
        if motion is not None
        else ConstantVectorSource([0.0])
        if scenario.disturbance.is_nominal
        else PhantomLiftSource(scenario.disturbance),
    )
    demux = builder.AddNamedSystem("ur3e_state_demux", Demultiplexer([6, 6]))

    # What the controllers read (through a FaultySensor with sensor faults).
    force = add_sensor_faults(
        builder, scenario, station.GetOutputPort("ft_sensor.force_W")
    )
    if scenario.controller_feedback == "command":
        tip = builder.AddNamedSystem(
            "commanded_tip",
            CommandedTipKinematics(
                scenario.station, period_s=scenario.controller.period_s, q0=q0
            ),
        )
        builder.Connect(fdcc.GetOutputPort("position_command"), tip.GetInputPort("q"))
        tip_position = tip.GetOutputPort("position")
        tip_velocity = tip.GetOutputPort("velocity")
    else:
        tip_position = station.GetOutputPort("probe.position")
        tip_velocity = station.GetOutputPort("probe.velocity")
    builder.Connect(tip_position, controller.GetInputPort("probe.position"))
    builder.Connect(tip_velocity, controller.GetInputPort("probe.velocity"))
    builder.Connect(force, controller.GetInputPort("ft_sensor.force_W"))
    builder.Connect(
        target.get_target_position_output_port(),
        controller.GetInputPort("target_position"),
    )
    builder.Connect(station.GetOutputPort("ur3e.state"), demux.get_input_port())
    # The FDCC reads its five inputs as one vector, built by a C++
    # Multiplexer: one port evaluation per tick instead of five.
    fdcc_inputs = AddFdccInputs(builder, fdcc)
    for source, part in (
        (demux.get_output_port(0), "joint_positions"),
        (target.get_target_position_output_port(), "target_position"),
        (controller.GetOutputPort("stiffness"), "stiffness"),
        (force, "ft_sensor.force_W"),
        (controller.GetOutputPort("target_force"), "target_force"),
    ):
        builder.Connect(source, fdcc_inputs[part])
    builder.Connect(
        fdcc.GetOutputPort("position_command"),
        station.GetInputPort("ur3e.position_command"),
    )
    # Port 0: the lift (a PatientMotionSource's second port is the lateral one).
    builder.Connect(lift.get_output_port(0), station.GetInputPort("phantom.lift"))
    if lateral:
        builder.Connect(
            motion.get_phantom_lateral_output_port(),
            station.GetInputPort("phantom.lateral"),
        )

    sources = {
        system.get_name(): system for system in (station, controller, fdcc, target)
    }
    logs = AddScanLogs(
        builder,
        {**log_group_ports(sources, lateral=lateral), **rig_log_ports(controller)},
        period_s=scenario.logging.period_s,
    )
    diagram = builder.Build()
    diagram.set_name("scan")
    return diagram, logs


def initial_joint_positions(scenario: Scenario) -> np.ndarray:
    """UR3e joints placing the probe tip at the start of the scan, tool down (IK).

    The tip starts at the target's start (x, y) and at
    ``trajectory.start_tip_z_m``.
    """
    x, y, _ = scenario.trajectory.start_xyz_m
    p_WP = np.array([x, y, scenario.trajectory.start_tip_z_m])
    return np.asarray(initial_q_for_tip(p_WP, scenario.station), float)


def set_initial_state(diagram, root_context, q0) -> None:
    """Starts the arm at rest at q0 and every joint-command state at q0, and
    the phantom at rest where its motion starts.

    Sets the station's state (``station.set_station_state``: plant at q0,
    the joint servo's state; the phantom's joints at their commands at t = 0,
    and their servo's state there) and the FDCC's command state, so the
    first commanded motion is zero, not a jump from zero angles, and a
    motion that starts off zero (a real log's replayed lift) does not drive
    the phantom into the probe in the first milliseconds.
    """
    station = diagram.GetSubsystemByName("station")
    station_context = station.GetMyMutableContextFromRoot(root_context)
    servo = station.GetSubsystemByName("phantom_lift_interpolator")
    servo_context = servo.GetMyMutableContextFromRoot(root_context)
    command = servo.get_input_port().Eval(servo_context)  # [lift(, x, y)], t = 0
    set_station_state(station, station_context, q0, phantom_command=command)
    servo.set_initial_position(servo_context, command)
    fdcc = diagram.GetSubsystemByName("fdcc")
    fdcc.set_initial_command(fdcc.GetMyMutableContextFromRoot(root_context), q0)


__all__ = [
    "CommandedTipKinematics",
    "MakeScanDiagram",
    "initial_joint_positions",
    "load_scenario_phantom",
    "set_initial_state",
]
