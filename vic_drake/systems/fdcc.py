"""FdccController: the FDCC layer as a 500 Hz discrete LeafSystem.

A thin adapter around :func:`vic_drake.control.fdcc.fdcc_tick` (the tick of
:func:`vic_drake.control.fdcc.fdcc_step`). Every ``FdccParams.period_s`` it
reads its inputs, runs one FDCC tick and stores the joint position command,
the internal joint velocity and the PD's last error in its discrete state.
The CS, CF and variable-stiffness controllers all drive it through
``stiffness`` and ``target_force``.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem

from vic_drake.control.fdcc import FdccConstants, FdccModel, FdccParams, fdcc_tick
from vic_drake.errors import VicDrakeError
from vic_drake.models.ur3e import MakeFdccModel


class FdccController(LeafSystem):
    """Forward dynamics compliance control of the UR3e probe.

    Input ports:
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

    State (discrete, updated every ``period_s``): the command q (6), the
    internal velocity (6) and the PD's last error (6), and the status (2).

    The settings are read once, at construction.
    """

    def __init__(
        self, params: FdccParams | None = None, *, station_params, initial_q=None
    ):
        """
        Args:
            params: the FDCC settings (default FdccParams()).
            station_params: tool geometry (probe offset) of the internal
                model, a :class:`vic_drake.station.StationParams` (required:
                this layer does not import the station).
            initial_q: default command, rad (6,); set it to the arm's start.
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
        self._q_port = self.DeclareVectorInputPort("joint_positions", 6)
        self._target_port = self.DeclareVectorInputPort("target_position", 3)
        self._stiffness_port = self.DeclareVectorInputPort("stiffness", 3)
        self._measured_port = self.DeclareVectorInputPort("ft_sensor.force_W", 3)
        self._target_force_port = self.DeclareVectorInputPort("target_force", 3)
        self._q_cmd = self.DeclareDiscreteState(q0)
        self._internal = self.DeclareDiscreteState(12)
        self._status = self.DeclareDiscreteState(2)
        self.DeclarePeriodicDiscreteUpdateEvent(
            self._params.period_s, 0.0, self._update
        )
        self._command_port = self.DeclareStateOutputPort(
            "position_command", self._q_cmd
        )
        self._status_port = self.DeclareStateOutputPort("status", self._status)
        self._groups = (int(self._q_cmd), int(self._internal), int(self._status))

    @property
    def params(self) -> FdccParams:
        return self._params

    @property
    def model(self) -> FdccModel:
        """The internal model (e.g. for forward kinematics of the probe)."""
        return self._model

    def get_joint_positions_input_port(self):
        return self._q_port

    def get_target_position_input_port(self):
        return self._target_port

    def get_stiffness_input_port(self):
        return self._stiffness_port

    def get_measured_force_input_port(self):
        return self._measured_port

    def get_target_force_input_port(self):
        return self._target_force_port

    def get_position_command_output_port(self):
        return self._command_port

    def get_status_output_port(self):
        return self._status_port

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
        command, internal, status = map(discrete_state.get_mutable_value, self._groups)
        result = fdcc_tick(
            self._model,
            self._constants,
            self._q_port.Eval(context),
            command,
            internal[:6],
            internal[6:],
            self._target_port.Eval(context),
            self._stiffness_port.Eval(context),
            self._measured_port.Eval(context),
            self._target_force_port.Eval(context),
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
