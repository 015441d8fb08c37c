"""StiffnessQpSystem: the per-tick stiffness QP as a discrete LeafSystem.

A thin wrapper over :mod:`vic_drake.control.stiffness_qp`: every period it
reads the measurement, the references and the tank energy, solves the QP
(or, for CS and CF, applies their constant stiffness) and stores in its
discrete state the stiffness, the damping, what the tick used for the tank
to integrate (the "qp_tick" record; see :mod:`vic_drake.systems.tank`) and
a status record. Each is published by a state output port; no solve
happens in an output.
"""

from __future__ import annotations

import copy
import math

import numpy as np
from pydrake.systems.framework import LeafSystem

from vic_drake.control.params import ControllerParams
from vic_drake.control.references import constant_stiffness
from vic_drake.control.stiffness_qp.problem import make_stiffness_qp_problem
from vic_drake.control.stiffness_qp.program import StiffnessQp
from vic_drake.systems.signals import (
    QP_TICK_ACTIVE,
    QP_TICK_DAMPING_USED,
    QP_TICK_POSITION_ERROR,
    QP_TICK_SIZE,
    QP_TICK_STIFFNESS,
    QP_TICK_VELOCITY_ERROR,
    REF_FAULT,
    REF_FORCE_MIN,
    REF_FORCE_REFERENCE,
    REF_IN_CONTACT,
    REF_PENETRATION,
    REFERENCES_SIZE,
    STATUS_FALLBACK_COUNT,
    STATUS_FIELDS,
    STATUS_QP_OK,
)

__all__ = ["STATUS_FIELDS", "StiffnessQpSystem"]


class StiffnessQpSystem(LeafSystem):
    """Diagonal stiffness from the QP of eq. 8 (or CS/CF's constant one).

    Input ports:
        probe.position (3): p_WP, m.
        probe.velocity (3): v_WP, m/s.
        target_position (3): x_d, m.
        references (13): ForceReferenceSystem's "references" (F_ref, F_min,
            target force, contact; layout in :mod:`vic_drake.systems.signals`).
        tank_energy (1): T before this tick, J (EnergyTankSystem's
            "tank_energy").

    Output ports (the last tick, from state):
        stiffness (3): K, N/m.
        damping (3): D = 2 zeta sqrt(K), N s/m (what the next tick's QP
            and the compliance stage use).
        qp_tick (13): what the tick used, for the tank: e = x_d - x,
            e_dot = -x_dot (both 0 on CS, CF and faulty ticks), K, the
            damping used, active (layout: the ``QP_TICK_*`` slices of
            :mod:`vic_drake.systems.signals`).
        status (6): :data:`vic_drake.systems.signals.STATUS_FIELDS`
            (qp_ok, fallback_count, fault, in_contact, solve_time_s,
            penetration_m).

    State (discrete): one group per output port, published as it is. K
    starts at K_min (constant stiffness for CS/CF).

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
            ("probe.position", 3),
            ("probe.velocity", 3),
            ("target_position", 3),
            ("references", REFERENCES_SIZE),
            ("tank_energy", 1),
        ):
            ports[name] = self.DeclareVectorInputPort(name, size)
        self._in = ports
        k0 = self._constant if self._constant is not None else self._k_min
        d0 = [2.0 * self._zeta * math.sqrt(k) for k in k0]
        status0 = np.zeros(len(STATUS_FIELDS))
        status0[STATUS_QP_OK] = 1.0
        self._index = {}
        self._out = {}
        tick0 = np.zeros(QP_TICK_SIZE)  # No tick yet: not active.
        tick0[QP_TICK_STIFFNESS] = k0
        tick0[QP_TICK_DAMPING_USED] = d0
        for name, value in (
            ("stiffness", k0),
            ("damping", d0),
            ("qp_tick", tick0),
            ("status", status0),
        ):
            self._index[name] = self.DeclareDiscreteState(np.asarray(value, float))
            self._out[name] = self.DeclareStateOutputPort(name, self._index[name])
        self.DeclarePeriodicDiscreteUpdateEvent(self._dt, 0.0, self._update)

    def _update(self, context, discrete_state):
        inp, index = self._in, self._index
        p_WP = inp["probe.position"].Eval(context).tolist()
        v_WP = inp["probe.velocity"].Eval(context).tolist()
        x_d = inp["target_position"].Eval(context).tolist()
        refs = inp["references"].Eval(context).tolist()
        energy = float(inp["tank_energy"].Eval(context)[0])
        k_prev = context.get_discrete_state(index["stiffness"]).value().tolist()
        count = context.get_discrete_state(index["status"]).GetAtIndex(
            STATUS_FALLBACK_COUNT
        )
        f_ref, f_min = refs[REF_FORCE_REFERENCE], refs[REF_FORCE_MIN]
        zeta = self._zeta
        d_used = (
            2.0 * zeta * math.sqrt(max(k_prev[0], 0.0)),
            2.0 * zeta * math.sqrt(max(k_prev[1], 0.0)),
            2.0 * zeta * math.sqrt(max(k_prev[2], 0.0)),
        )
        # A sum of floats is finite iff every term is (inf - inf = nan).
        total = sum(p_WP) + sum(v_WP) + sum(x_d) + sum(refs) + energy
        fault = not math.isfinite(total) or refs[REF_FAULT] > 0.5
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
        tick = [0.0] * QP_TICK_SIZE
        tick[QP_TICK_POSITION_ERROR] = e
        tick[QP_TICK_VELOCITY_ERROR] = e_dot
        tick[QP_TICK_STIFFNESS] = k
        tick[QP_TICK_DAMPING_USED] = d_used
        tick[QP_TICK_ACTIVE] = active
        in_contact = 0.0 if fault else refs[REF_IN_CONTACT]
        pen = refs[REF_PENETRATION] if math.isfinite(refs[REF_PENETRATION]) else 0.0
        for name, value in (
            ("stiffness", k),
            ("damping", [2.0 * zeta * math.sqrt(max(k_i, 0.0)) for k_i in k]),
            ("qp_tick", tick),
            # In the order of STATUS_FIELDS.
            (
                "status",
                [qp_ok, count, 1.0 if fault else 0.0, in_contact, solve_time, pen],
            ),
        ):
            discrete_state.set_value(index[name], value)

    def get_stiffness_output_port(self):
        return self._out["stiffness"]

    def get_damping_output_port(self):
        return self._out["damping"]

    def get_qp_tick_output_port(self):
        return self._out["qp_tick"]

    def get_status_output_port(self):
        return self._out["status"]
