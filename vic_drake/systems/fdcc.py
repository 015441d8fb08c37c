"""FdccController: the FDCC layer as a 500 Hz discrete LeafSystem.

A thin adapter around :func:`vic_drake.control.fdcc.fdcc_tick` (the tick of
:func:`vic_drake.control.fdcc.fdcc_step`). Every ``FdccParams.period_s`` it
reads its inputs, runs one FDCC tick and stores the joint position command,
the internal joint velocity and the PD's last error in its discrete state.
The CS, CF and variable-stiffness controllers all drive it through
the stiffness and target force parts of its one "inputs" vector, which
:func:`AddFdccInputs` builds with a C++ Multiplexer.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem
from pydrake.systems.primitives import Multiplexer

from vic_drake.control.fdcc import FdccConstants, FdccModel, FdccParams, fdcc_tick
from vic_drake.control.watchdog import (
    TRIPPED,
    SensorWatchdogParams,
    initial_watchdog_state,
    record_trip,
    retract_target,
    watch_reading,
)
from vic_drake.errors import VicDrakeError
from vic_drake.models.ur3e import MakeFdccModel
from vic_drake.systems.signals import (
    FDCC_IN_FORCE,
    FDCC_IN_JOINT_POSITIONS,
    FDCC_IN_STIFFNESS,
    FDCC_IN_TARGET_FORCE,
    FDCC_IN_TARGET_POSITION,
    FDCC_INPUT_PARTS,
    FDCC_INPUTS_SIZE,
    widths,
)


class FdccController(LeafSystem):
    """Forward dynamics compliance control of the UR3e probe.

    Input port:
        inputs (18, ``signals.FDCC_INPUTS_SIZE``): one vector of five parts
        (``signals.FDCC_INPUT_PARTS``, the ``FDCC_IN_*`` slices), built in
        a Diagram by :func:`AddFdccInputs`:
        joint_positions (6): measured joint angles, rad.
        target_position (3): target probe tip position x_d in W, m (the
            orientation target is FdccParams.target_orientation_wxyz, the
            tool pointing straight down).
        stiffness (3): diagonal translational stiffness K, N/m (>= 0).
        ft_sensor.force_W (3): F/T force in W, N, sensor convention (negative
            z = pressing into the body).
        target_force (3): force target in W, N, same convention (e.g.
            (0, 0, -7) to press with 7 N; zero for pure compliance).
    Output ports:
        position_command (6): joint position command, rad (a state output).
        status (2): (fault on the last tick, number of faulted ticks). A
            fault -- a non-finite input or result, or a negative stiffness --
            holds the previous command and zeroes the internal velocity.
        watchdog (13, ``control.watchdog.WATCHDOG_FIELDS``): the force
            sensor's watchdog (all zeros but the NaN fields when disabled).

    State (discrete, updated every ``period_s``): the command q (6), the
    internal velocity (6) and the PD's last error (6), the status (2) and
    the watchdog (13).

    With a watchdog (``watchdog.enabled``), a force channel that keeps its
    value while the others change, or a reading that stops changing
    altogether, trips it (:mod:`vic_drake.control.watchdog`);
    from then on the tick ignores the sensor, the stiffness and the targets
    of its inputs and lifts the probe away from the tissue
    (:func:`~vic_drake.control.watchdog.retract_target`).

    The settings are read once, at construction.
    """

    def __init__(
        self,
        params: FdccParams | None = None,
        *,
        station_params,
        initial_q=None,
        watchdog: SensorWatchdogParams | None = None,
    ):
        """
        Args:
            params: the FDCC settings (default FdccParams()).
            station_params: tool geometry (probe offset) of the internal
                model, a :class:`vic_drake.station.StationParams` (required:
                this layer does not import the station).
            initial_q: default command, rad (6,); set it to the arm's start.
            watchdog: the force sensor's watchdog (default: none; the scan
                diagram passes the scenario's).
        """
        super().__init__()
        self._params = params or FdccParams()
        if not isinstance(self._params, FdccParams):
            raise VicDrakeError(
                f"params must be FdccParams, got {type(params).__name__}"
            )
        self._model = MakeFdccModel(self._params, station_params)
        self._R_WP_target = self._params.R_WP_target
        self._constants = FdccConstants.from_params(self._params, self._R_WP_target)
        q0 = np.zeros(6) if initial_q is None else np.asarray(initial_q, float)
        if q0.shape != (6,) or not np.all(np.isfinite(q0)):
            raise VicDrakeError(
                f"initial_q must be 6 finite joint angles (rad), got {initial_q!r}"
            )
        if watchdog is not None and not isinstance(watchdog, SensorWatchdogParams):
            raise VicDrakeError(
                f"watchdog must be SensorWatchdogParams or None, got {watchdog!r}"
            )
        self._watchdog = (
            watchdog.validate() if watchdog is not None and watchdog.enabled else None
        )
        if self._watchdog is not None:
            self._window = self._watchdog.window_ticks(self._params.period_s)
            self._dead_window = self._watchdog.dead_ticks(self._params.period_s)
            k = self._watchdog.retract_stiffness_N_per_m
            self._retract_stiffness = np.array([k, k, k])
        self._inputs_port = self.DeclareVectorInputPort("inputs", FDCC_INPUTS_SIZE)
        self._q_cmd = self.DeclareDiscreteState(q0)
        self._internal = self.DeclareDiscreteState(12)
        self._status = self.DeclareDiscreteState(2)
        self._watch = self.DeclareDiscreteState(initial_watchdog_state())
        self.DeclarePeriodicDiscreteUpdateEvent(
            self._params.period_s, 0.0, self._update
        )
        self._command_port = self.DeclareStateOutputPort(
            "position_command", self._q_cmd
        )
        self._status_port = self.DeclareStateOutputPort("status", self._status)
        self._watchdog_port = self.DeclareStateOutputPort("watchdog", self._watch)
        self._groups = (
            int(self._q_cmd),
            int(self._internal),
            int(self._status),
            int(self._watch),
        )

    @property
    def params(self) -> FdccParams:
        return self._params

    @property
    def model(self) -> FdccModel:
        """The internal model (e.g. for forward kinematics of the probe)."""
        return self._model

    def get_inputs_input_port(self):
        return self._inputs_port

    def get_position_command_output_port(self):
        return self._command_port

    def get_status_output_port(self):
        return self._status_port

    def get_watchdog_output_port(self):
        return self._watchdog_port

    def watchdog_state(self, context) -> np.ndarray:
        """A copy of the watchdog's state (``control.watchdog.WATCHDOG_SIZE``) in ``context``."""
        return np.array(context.get_discrete_state(self._watch).get_value())

    def set_initial_command(self, context, q) -> None:
        """Sets the command state to q (6,), rad, with zero internal motion."""
        q = np.asarray(q, float)
        if q.shape != (6,) or not np.all(np.isfinite(q)):
            raise VicDrakeError(f"q must be 6 finite joint angles (rad), got {q!r}")
        context.SetDiscreteState(self._q_cmd, q)
        context.SetDiscreteState(self._internal, np.zeros(12))

    def _update(self, context, discrete_state):
        # Drake fills discrete_state with the current state before calling
        # this handler: each group is read and written in place.
        command, internal, status, watch = map(
            discrete_state.get_mutable_value, self._groups
        )
        u = self._inputs_port.Eval(context)
        q = u[FDCC_IN_JOINT_POSITIONS]
        x_d = u[FDCC_IN_TARGET_POSITION]
        stiffness = u[FDCC_IN_STIFFNESS]
        force = u[FDCC_IN_FORCE]
        target_force = u[FDCC_IN_TARGET_FORCE]
        if self._watchdog is not None:
            channel = watch_reading(watch, force, self._window, self._dead_window)
            if channel >= 0:
                tip = self._model.pose(q).translation()
                record_trip(watch, channel, context.get_time(), tip)
            if watch[TRIPPED] >= 0.5:  # The sensor is not read again.
                x_d = retract_target(watch, context.get_time(), self._watchdog)
                stiffness = self._retract_stiffness
                force = target_force = _ZERO3
        result = fdcc_tick(
            self._model,
            self._constants,
            q,
            command,
            internal[:6],
            internal[6:],
            x_d,
            stiffness,
            force,
            target_force,
        )
        if result is None:  # Hold the command, stop the internal motion.
            internal[:] = 0.0
            status[0] = 1.0
            status[1] = status[1] + 1.0
        else:
            q, qd, err = result
            command[:] = q
            internal[:] = qd + err
            status[0] = 0.0
            status[1] = status[1] + 0.0


_ZERO3 = np.zeros(3)


def AddFdccInputs(builder, fdcc: FdccController, *, name: str = "fdcc_inputs"):
    """Adds the C++ Multiplexer that builds ``fdcc``'s "inputs" vector.

    Args:
        builder: the DiagramBuilder holding ``fdcc``.
        fdcc: the FdccController whose "inputs" port the Multiplexer feeds.
        name: the Multiplexer's name in the Diagram.

    Returns:
        The Multiplexer's input port of each part, by the part's name in
        :data:`vic_drake.systems.signals.FDCC_INPUT_PARTS` ("joint_positions",
        "target_position", "stiffness", "ft_sensor.force_W", "target_force"),
        for the caller to connect or fix.
    """
    mux = builder.AddNamedSystem(
        name, Multiplexer(widths(part for _, part in FDCC_INPUT_PARTS))
    )
    builder.Connect(mux.get_output_port(0), fdcc.get_inputs_input_port())
    return {part: mux.get_input_port(i) for i, (part, _) in enumerate(FDCC_INPUT_PARTS)}
