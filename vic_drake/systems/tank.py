"""EnergyTankSystem: the paper's energy tank as a discrete LeafSystem.

The tank and the stiffness QP are coupled inside one tick: the QP at tick n
uses T after tick n-1, and the tank at tick n integrates the power of the
stiffness the QP chose at tick n. Drake's simultaneous discrete updates
cannot chain two systems within a tick, so the QP system publishes, in its
state, the "commit" of its last tick (e, e_dot, K, D, dt, active) and the
tank's outputs are T_state advanced by that commit (cheap algebra, no
solve). The periodic update then stores that value. Both systems thus see
exactly the sequence of the real controller, with no lag.
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

#: Layout of the QP system's "commit" vector read by the tank.
COMMIT_SIZE = 14
COMMIT_E = slice(0, 3)
COMMIT_E_DOT = slice(3, 6)
COMMIT_K = slice(6, 9)
COMMIT_D = slice(9, 12)
COMMIT_DT = 12
COMMIT_ACTIVE = 13


class EnergyTankSystem(LeafSystem):
    """Energy tank x_t (T = x_t^2 / 2), updated at the controller rate.

    Input ports:
        commit (14): [e (3, m), e_dot (3, m/s), K (3, N/m), D (3, N s/m),
            dt (s), active (0/1)] of the stiffness QP's last tick.

    Output ports:
        tank (4): [T_J, power_W, sigma, enabled] after the committed tick
            (power 0, sigma 0, enabled 0 when the tick was inactive: CS, CF).
        energy (1): T_J, what the next QP tick sees.
        x_t (1): the tank state (before the committed tick).

    State: x_t (1), discrete.
    """

    def __init__(self, params: ControllerParams):
        super().__init__()
        # A private copy: later edits of the caller's (mutable) params cannot
        # change a built system.
        params = copy.deepcopy(params).validate()
        self._tank = params.tank
        self._k_min = tuple(params.qp.stiffness_min_N_per_m)
        self._commit_port = self.DeclareVectorInputPort("commit", COMMIT_SIZE)
        self._state_index = self.DeclareDiscreteState(
            [tank_state(params.tank.initial_energy_J)]
        )
        self.DeclarePeriodicDiscreteUpdateEvent(params.period_s, 0.0, self._update)
        self.DeclareStateOutputPort("x_t", self._state_index)
        self._tank_port = self.DeclareVectorOutputPort(
            "tank",
            4,
            self._calc_tank,
            {self.xd_ticket(), self.all_input_ports_ticket()},
        )
        self._energy_port = self.DeclareVectorOutputPort(
            "energy",
            1,
            self._calc_energy,
            {self.xd_ticket(), self.all_input_ports_ticket()},
        )

    def _step(self, context) -> TankStep:
        energy = tank_energy(
            context.get_discrete_state(self._state_index).GetAtIndex(0)
        )
        c = self._commit_port.Eval(context).tolist()
        if c[COMMIT_ACTIVE] < 0.5:
            return TankStep(energy, 0.0, 0.0, False)
        return tank_step(
            energy, c[COMMIT_E], c[COMMIT_E_DOT], c[COMMIT_K], self._k_min, c[COMMIT_D],
            c[COMMIT_DT], self._tank,
        )  # fmt: skip

    def _calc_tank(self, context, output: BasicVector):
        s = self._step(context)
        output.SetFromVector(
            [s.energy_J, s.power_W, s.sigma, 1.0 if s.enabled else 0.0]
        )

    # "energy" and the update read the cached "tank" output: one tank step per tick.
    def _calc_energy(self, context, output: BasicVector):
        output.SetAtIndex(0, self._tank_port.Eval(context)[0])

    def _update(self, context, discrete_state):
        discrete_state.get_mutable_vector(self._state_index).SetAtIndex(
            0, tank_state(float(self._tank_port.Eval(context)[0]))
        )

    def get_commit_input_port(self):
        return self._commit_port

    def get_tank_output_port(self):
        return self._tank_port

    def get_energy_output_port(self):
        return self._energy_port
