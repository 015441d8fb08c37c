"""EnergyTankSystem: the paper's energy tank as a discrete LeafSystem.

The tank and the stiffness QP are coupled inside one tick: the QP at tick n
uses T after tick n-1, and the tank at tick n integrates the power of the
stiffness the QP chose at tick n. Drake's simultaneous discrete updates
cannot chain two systems within a tick, so the QP system publishes, from
its state, what its last tick used (its "qp_tick" record: position error,
velocity error, stiffness, damping, active) and the tank's outputs are
T_state advanced by that tick (cheap algebra, no solve). The periodic update then stores that value.
Both systems thus see exactly the sequence of the real controller, with no
lag.
"""

from __future__ import annotations

import copy

from pydrake.systems.framework import BasicVector, LeafSystem

from vic_drake.control.params import ControllerParams
from vic_drake.control.tank import (
    TankStep,
    tank_energy,
    tank_state,
    tank_step,
)
from vic_drake.systems.signals import (
    QP_TICK_ACTIVE,
    QP_TICK_DAMPING_USED,
    QP_TICK_POSITION_ERROR,
    QP_TICK_SIZE,
    QP_TICK_STIFFNESS,
    QP_TICK_VELOCITY_ERROR,
    TANK_ENERGY,
    TANK_FIELDS,
)

__all__ = ["EnergyTankSystem", "TANK_FIELDS"]


class EnergyTankSystem(LeafSystem):
    """Energy tank x_t (T = x_t^2 / 2), updated at the controller rate.

    Input ports:
        qp_tick (13): StiffnessQpSystem's record of its last tick: e
            (m), e_dot (m/s), K (N/m), the damping used (N s/m), active
            (layout: the ``QP_TICK_*`` slices of
            :mod:`vic_drake.systems.signals`). On an inactive tick (before
            the QP's first, CS and CF): power 0, sigma 0, enabled 0, T
            constant.

    The tick lasts ``params.period_s``.

    Output ports:
        tank (4): :data:`vic_drake.systems.signals.TANK_FIELDS` (T_J,
            power_W, sigma, enabled) after the QP's last tick.
        tank_energy (1): T_J, what the next QP tick sees.
        x_t (1): the tank state (before the QP's last tick).

    State: x_t (1), discrete.
    """

    def __init__(self, params: ControllerParams):
        super().__init__()
        # A private copy: later edits of the caller's (mutable) params cannot
        # change a built system.
        params = copy.deepcopy(params).validate()
        self._tank = params.tank
        self._k_min = tuple(params.qp.stiffness_min_N_per_m)
        self._dt = float(params.period_s)
        self._tick_port = self.DeclareVectorInputPort("qp_tick", QP_TICK_SIZE)
        self._state_index = self.DeclareDiscreteState(
            [tank_state(params.tank.initial_energy_J)]
        )
        self.DeclarePeriodicDiscreteUpdateEvent(params.period_s, 0.0, self._update)
        self.DeclareStateOutputPort("x_t", self._state_index)
        self._tank_port = self.DeclareVectorOutputPort(
            "tank",
            len(TANK_FIELDS),
            self._calc_tank,
            {self.xd_ticket(), self.all_input_ports_ticket()},
        )
        self._energy_port = self.DeclareVectorOutputPort(
            "tank_energy",
            1,
            self._calc_energy,
            {self.xd_ticket(), self.all_input_ports_ticket()},
        )

    def _step(self, context) -> TankStep:
        # x_t is the only state group.
        energy = tank_energy(context.get_discrete_state_vector().GetAtIndex(0))
        tick = self._tick_port.Eval(context).tolist()
        if tick[QP_TICK_ACTIVE] < 0.5:
            return TankStep(energy, 0.0, 0.0, False)
        return tank_step(
            energy,
            tick[QP_TICK_POSITION_ERROR],
            tick[QP_TICK_VELOCITY_ERROR],
            tick[QP_TICK_STIFFNESS],
            self._k_min,
            tick[QP_TICK_DAMPING_USED],
            self._dt,
            self._tank,
        )

    def _calc_tank(self, context, output: BasicVector):
        energy, power, sigma, enabled = self._step(context)
        # In the order of TANK_FIELDS, through a numpy view (SetFromVector
        # converts a Python sequence: costlier).
        out = output.get_mutable_value()
        out[0], out[1], out[2], out[3] = energy, power, sigma, 1.0 if enabled else 0.0

    # "tank_energy" and the update read the cached "tank" output: one tank
    # step per tick.
    def _calc_energy(self, context, output: BasicVector):
        output.SetAtIndex(0, self._tank_port.Eval(context)[TANK_ENERGY])

    def _update(self, context, discrete_state):
        discrete_state.get_mutable_value(self._state_index)[0] = tank_state(
            float(self._tank_port.Eval(context)[TANK_ENERGY])
        )

    def get_qp_tick_input_port(self):
        return self._tick_port

    def get_tank_output_port(self):
        return self._tank_port

    def get_energy_output_port(self):
        return self._energy_port
