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
    QP_IN_REFERENCE_TICK,
    QP_IN_TANK_ENERGY,
    QP_IN_TARGET,
    QP_INPUTS_SIZE,
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
    REF_PROBE_POSITION,
    REF_PROBE_VELOCITY,
    STATUS_FALLBACK_COUNT,
    STATUS_FIELDS,
    STATUS_QP_OK,
)

_STATUS_FAULT = STATUS_FIELDS.index("fault")
_STATUS_IN_CONTACT = STATUS_FIELDS.index("in_contact")
_STATUS_SOLVE_TIME = STATUS_FIELDS.index("solve_time_s")
_STATUS_PENETRATION = STATUS_FIELDS.index("penetration_m")

__all__ = ["STATUS_FIELDS", "StiffnessQpSystem"]


class StiffnessQpSystem(LeafSystem):
    """Diagonal stiffness from the QP of eq. 8 (or CS/CF's constant one).

    Input port:
        inputs (23): one vector (layout: ``QP_INPUTS_SIZE`` and the
            ``QP_IN_*`` parts of :mod:`vic_drake.systems.signals`):
            x_d (3, m); the "reference_tick" (19), the head of
            ForceReferenceSystem's "tick" output: its "references" (F_ref,
            F_min, target force, contact), then the probe position p_WP (m)
            and velocity v_WP (m/s) that tick read (the ``REF_*`` slices);
            and T before this tick (1, J; EnergyTankSystem's
            "tank_energy", in MakeVariableImpedanceController element
            TANK_ENERGY of its "tank" record). The controller Diagram builds
            it with a C++ Multiplexer ("qp_inputs").

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
        self._min_energy = float(params.tank.min_energy_J)
        self._solve = (
            None
            if self._constant is not None
            else StiffnessQp(qp.solver, osqp_eps=qp.osqp_eps).solve
        )
        self._inputs = self.DeclareVectorInputPort("inputs", QP_INPUTS_SIZE)
        k0 = self._constant if self._constant is not None else self._k_min
        d0 = [2.0 * self._zeta * math.sqrt(k) for k in k0]
        status0 = np.zeros(len(STATUS_FIELDS))
        status0[STATUS_QP_OK] = 1.0
        self._index = {}
        self._out = {}
        tick0 = np.zeros(QP_TICK_SIZE)  # No tick yet: not active.
        tick0[QP_TICK_STIFFNESS] = k0
        tick0[QP_TICK_DAMPING_USED] = d0
        # Every tick's qp_tick starts from this list (active: 1 for VS, 0 for CS/CF).
        self._tick_template = [0.0] * QP_TICK_SIZE
        self._tick_template[QP_TICK_ACTIVE] = 0.0 if self._constant is not None else 1.0
        for name, value in (
            ("stiffness", k0),
            ("damping", d0),
            ("qp_tick", tick0),
            ("status", status0),
        ):
            self._index[name] = self.DeclareDiscreteState(np.asarray(value, float))
            self._out[name] = self.DeclareStateOutputPort(name, self._index[name])
        self._state_groups = tuple(
            self._index[name] for name in ("stiffness", "damping", "qp_tick", "status")
        )
        # Scratch for the update: every group is written through these numpy
        # views, then copied into the update's result with one SetFrom (four
        # get_mutable_value calls cost more). Only the update uses it, and it
        # overwrites all of it each time.
        self._scratch = self.AllocateDiscreteVariables()
        self._scratch_views = tuple(
            self._scratch.get_mutable_value(index) for index in self._state_groups
        )
        self.DeclarePeriodicDiscreteUpdateEvent(self._dt, 0.0, self._update)

    def _update(self, context, discrete_state):
        # On entry discrete_state holds the current state (a LeafSystem copies
        # it in before calling an update handler): K and the fallback count
        # are read there.
        inputs = self._inputs.Eval(context).tolist()
        x_d = inputs[QP_IN_TARGET]
        refs = inputs[QP_IN_REFERENCE_TICK]
        p_WP, v_WP = refs[REF_PROBE_POSITION], refs[REF_PROBE_VELOCITY]
        energy = inputs[QP_IN_TANK_ENERGY]
        i_k, _, _, i_status = self._state_groups
        k_prev = discrete_state.value(i_k).tolist()
        zeta2 = 2.0 * self._zeta
        d_used = (
            zeta2 * math.sqrt(max(k_prev[0], 0.0)),
            zeta2 * math.sqrt(max(k_prev[1], 0.0)),
            zeta2 * math.sqrt(max(k_prev[2], 0.0)),
        )
        # A sum of floats is finite iff every term is (inf - inf = nan).
        total = sum(inputs)  # x_d, the references, p_WP, v_WP and T
        fault = not math.isfinite(total) or refs[REF_FAULT] > 0.5
        e = e_dot = (0.0, 0.0, 0.0)
        ok, solve_time = True, 0.0
        if fault:
            k = self._k_min
            ok = False
        elif self._constant is not None:
            k = self._constant
        else:
            e = (x_d[0] - p_WP[0], x_d[1] - p_WP[1], x_d[2] - p_WP[2])
            e_dot = (-v_WP[0], -v_WP[1], -v_WP[2])
            if energy < self._min_energy:
                k = self._k_min
            else:
                problem = make_stiffness_qp_problem(
                    e, e_dot, d_used, refs[REF_FORCE_REFERENCE], refs[REF_FORCE_MIN],
                    energy, self._dt, self._params.qp, self._params.tank,
                )  # fmt: skip
                # The solvers that take an initial guess start from the last K.
                sol = self._solve(problem, guess=k_prev)
                k = sol.stiffness
                solve_time = sol.solve_time_s
                ok = sol.success
        # Written through numpy views of the scratch (an element store costs
        # far less than converting a Python sequence), then one SetFrom.
        out_k, out_d, out_tick, status = self._scratch_views
        k0, k1, k2 = k
        out_k[0], out_k[1], out_k[2] = k0, k1, k2
        out_d[0] = zeta2 * math.sqrt(max(k0, 0.0))
        out_d[1] = zeta2 * math.sqrt(max(k1, 0.0))
        out_d[2] = zeta2 * math.sqrt(max(k2, 0.0))
        tick = self._tick_template.copy()
        tick[QP_TICK_POSITION_ERROR] = e
        tick[QP_TICK_VELOCITY_ERROR] = e_dot
        tick[QP_TICK_STIFFNESS] = k
        tick[QP_TICK_DAMPING_USED] = d_used
        out_tick[:] = tick
        fallbacks = discrete_state.value(i_status)[STATUS_FALLBACK_COUNT]
        if ok:
            status[STATUS_QP_OK] = 1.0
            status[STATUS_FALLBACK_COUNT] = fallbacks
        else:
            status[STATUS_QP_OK] = 0.0
            status[STATUS_FALLBACK_COUNT] = fallbacks + 1.0
        status[_STATUS_FAULT] = 1.0 if fault else 0.0
        status[_STATUS_IN_CONTACT] = 0.0 if fault else refs[REF_IN_CONTACT]
        status[_STATUS_SOLVE_TIME] = solve_time
        pen = refs[REF_PENETRATION]
        status[_STATUS_PENETRATION] = pen if math.isfinite(pen) else 0.0
        discrete_state.SetFrom(self._scratch)

    def get_inputs_input_port(self):
        return self._inputs

    def get_stiffness_output_port(self):
        return self._out["stiffness"]

    def get_damping_output_port(self):
        return self._out["damping"]

    def get_qp_tick_output_port(self):
        return self._out["qp_tick"]

    def get_status_output_port(self):
        return self._out["status"]
