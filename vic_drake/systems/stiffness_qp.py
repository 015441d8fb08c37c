"""StiffnessQpSystem: the per-tick stiffness QP as a discrete LeafSystem.

A thin wrapper over :mod:`vic_drake.control.stiffness_qp`: every period it
reads the measurement, the references and the tank energy, solves the QP
(or, for CS and CF, applies their constant stiffness) and stores the
stiffness, the inputs it used (the "commit" the tank integrates, see
:mod:`vic_drake.systems.tank`) and a status record in its discrete state.
Output ports only read that state; no solve happens in an output.
"""

from __future__ import annotations

import copy
import math

import numpy as np
from pydrake.systems.framework import LeafSystem

from vic_drake.control.params import ControllerParams
from vic_drake.control.references import constant_stiffness
from vic_drake.control.stiffness_qp import StiffnessQp, make_stiffness_qp_problem
from vic_drake.systems.tank import COMMIT_SIZE

#: Layout of the "status" output (and state group).
STATUS_FIELDS = (
    "qp_ok",
    "fallback_count",
    "fault",
    "in_contact",
    "solve_time_s",
    "penetration_m",
)


class StiffnessQpSystem(LeafSystem):
    """Diagonal stiffness from the QP of eq. 8 (or CS/CF's constant one).

    Input ports:
        ee_position (3): p_WP, m.
        ee_velocity (3): v_WP, m/s.
        target_position (3): x_d, m.
        references (13): ForceReferenceSystem's "references": [F_ref (3, N),
            F_min (3, N), target force (3, N), in_contact, penetration_m,
            fault, surface_velocity_m_per_s].
        tank_energy (1): T before this tick, J (EnergyTankSystem "energy").

    Output ports:
        stiffness (3): K, N/m.
        damping (3): D = 2 zeta sqrt(K), N s/m (what the next tick's QP
            and the compliance stage use).
        commit (14): [e, e_dot, K, D_used, dt, active] of the last tick.
        status (6): [qp_ok, fallback_count, fault, in_contact,
            solve_time_s, penetration_m].

    State (discrete): commit (14), status (6), K (3) and D (3), all
    published as they are. K starts at K_min (constant stiffness for CS/CF).

    Fallbacks: a failed or infeasible solve, or a non-finite input (fault),
    gives K = K_min, qp_ok = 0 and increments fallback_count. With the tank
    below T_min the VS controllers use K_min by design (qp_ok stays 1; the
    tank output's "enabled" is 0). CS and CF never run the QP (qp_ok = 1).
    """

    def __init__(self, params: ControllerParams):
        super().__init__()
        # A private copy: later edits of the caller's (mutable) params cannot
        # change a built system.
        params = copy.deepcopy(params).validate()
        self._params = params
        qp = params.qp
        self._k_min = tuple(float(v) for v in qp.stiffness_min_N_per_m)
        self._zeta = float(qp.damping_ratio)
        self._dt = float(params.period_s)
        self._constant = constant_stiffness(params.reference)
        self._solver = (
            None
            if self._constant is not None
            else StiffnessQp(qp.solver, osqp_eps=qp.osqp_eps)
        )
        ports = {}
        for name, size in (
            ("ee_position", 3),
            ("ee_velocity", 3),
            ("target_position", 3),
            ("references", 13),
            ("tank_energy", 1),
        ):
            ports[name] = self.DeclareVectorInputPort(name, size)
        self._in = ports
        k0 = self._constant if self._constant is not None else self._k_min
        commit0 = np.zeros(COMMIT_SIZE)
        commit0[6:9] = k0
        commit0[9:12] = [2.0 * self._zeta * math.sqrt(k) for k in k0]
        self._commit_index = self.DeclareDiscreteState(commit0)
        self._status_index = self.DeclareDiscreteState(
            np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        )
        # K and D again, each its own group so the ports publish state (no
        # Python per evaluation).
        self._stiffness_index = self.DeclareDiscreteState(commit0[6:9])
        self._damping_index = self.DeclareDiscreteState(commit0[9:12])
        self.DeclarePeriodicDiscreteUpdateEvent(self._dt, 0.0, self._update)
        self._stiffness_port = self.DeclareStateOutputPort(
            "stiffness", self._stiffness_index
        )
        self._damping_port = self.DeclareStateOutputPort("damping", self._damping_index)
        self._commit_port = self.DeclareStateOutputPort("commit", self._commit_index)
        self._status_port = self.DeclareStateOutputPort("status", self._status_index)

    def _update(self, context, discrete_state):
        inp = self._in
        p_WP = inp["ee_position"].Eval(context).tolist()
        v_WP = inp["ee_velocity"].Eval(context).tolist()
        x_d = inp["target_position"].Eval(context).tolist()
        refs = inp["references"].Eval(context).tolist()
        energy = float(inp["tank_energy"].Eval(context)[0])
        commit_old = context.get_discrete_state(self._commit_index).value().tolist()
        count = context.get_discrete_state(self._status_index).GetAtIndex(1)
        f_ref, f_min = refs[0:3], refs[3:6]
        zeta = self._zeta
        k_prev = commit_old[6:9]
        d_used = (
            2.0 * zeta * math.sqrt(max(k_prev[0], 0.0)),
            2.0 * zeta * math.sqrt(max(k_prev[1], 0.0)),
            2.0 * zeta * math.sqrt(max(k_prev[2], 0.0)),
        )
        # A sum of floats is finite iff every term is (inf - inf = nan).
        total = sum(p_WP) + sum(v_WP) + sum(x_d) + sum(refs) + energy
        fault = not math.isfinite(total) or refs[11] > 0.5
        e = (0.0, 0.0, 0.0)
        e_dot = (0.0, 0.0, 0.0)
        qp_ok, solve_time = 1.0, 0.0
        active = 0.0 if self._constant is not None else 1.0
        if fault:
            k = self._k_min
            qp_ok = 0.0
            count += 1.0
        elif self._constant is not None:
            k = self._constant
        else:
            e = (x_d[0] - p_WP[0], x_d[1] - p_WP[1], x_d[2] - p_WP[2])
            e_dot = (-v_WP[0], -v_WP[1], -v_WP[2])
            if energy < self._params.tank.min_energy_J:
                k = self._k_min
            else:
                problem = make_stiffness_qp_problem(
                    e, e_dot, d_used, f_ref, f_min, energy, self._dt,
                    self._params.qp, self._params.tank,
                )  # fmt: skip
                sol = self._solver.solve(problem, guess=k_prev)  # Warm start (OSQP).
                k = sol.stiffness
                solve_time = sol.solve_time_s
                if not sol.success:
                    qp_ok = 0.0
                    count += 1.0
        commit = discrete_state.get_mutable_vector(self._commit_index)
        commit.SetFromVector([*e, *e_dot, *k, *d_used, self._dt, active])
        discrete_state.get_mutable_vector(self._stiffness_index).SetFromVector(k)
        discrete_state.get_mutable_vector(self._damping_index).SetFromVector(
            [2.0 * zeta * math.sqrt(max(k_i, 0.0)) for k_i in k]
        )
        status = discrete_state.get_mutable_vector(self._status_index)
        in_contact = 0.0 if fault else refs[9]
        pen = refs[10] if math.isfinite(refs[10]) else 0.0
        status.SetFromVector(
            [qp_ok, count, 1.0 if fault else 0.0, in_contact, solve_time, pen]
        )

    def get_stiffness_output_port(self):
        return self._stiffness_port

    def get_damping_output_port(self):
        return self._damping_port

    def get_commit_output_port(self):
        return self._commit_port

    def get_status_output_port(self):
        return self._status_port
