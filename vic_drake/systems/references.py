"""ForceReferenceSystem: contact, penetration rate and force references.

A thin LeafSystem over :mod:`vic_drake.control.references`. The references
are cheap algebra on the current measurement, so they are computed in a
cache entry with direct feedthrough (the "references" and "target_force"
ports: the real controller computed them from the same sample as its QP,
and the QP and FDCC read them within the same tick). The periodic discrete
update at the controller rate advances the surface-velocity filter and
stores the tick's values, which the "force_reference", "force_min" and
"contact" ports publish from state: what the QP used at the last tick
(loggers read them after the tick's update without recomputing).
"""

from __future__ import annotations

import copy
import math

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, LeafSystem, ValueProducer

from vic_drake.control.params import ControllerParams
from vic_drake.control.references import (
    force_references,
    in_contact,
    penetration,
    penetration_rate,
    scalar_sampler,
    surface_velocity_gradient,
    surface_velocity_initial_state,
    surface_velocity_step,
)
from vic_drake.tissue.phantom import Phantom


class ForceReferenceSystem(LeafSystem):
    """Force references of the selected controller (CS, CF, VS-CF, VS-VF).

    Input ports:
        ee_position (3): probe tip p_WP, m.
        ee_velocity (3): v_WP, m/s.
        measured_force (3): F/T force in W, N, sensor convention.

    Output ports (direct feedthrough of the current inputs):
        target_force (3): force the FDCC stage tracks, N (CF only).
        references (13): [F_ref (3), F_min (3), target force (3), contact
            (4)] (see below), read by StiffnessQpSystem in one port
            evaluation.
    Output ports (state: the values of the last tick):
        force_reference (3): F_ref, N (sensor convention).
        force_min (3): F_min, N.
        contact (4): [in_contact (0/1), penetration_m, fault (0/1),
            surface_velocity_m_per_s].

    State: the surface-velocity filter and the last tick's F_ref, F_min,
    contact (discrete, updated every period).
    A non-finite input gives F_ref = 0, F_min = (F_min,x, F_min,y,
    -F_max,z), target 0, in_contact 0 and fault 1 (never a NaN output).
    """

    def __init__(self, params: ControllerParams, *, phantom: Phantom):
        super().__init__()
        # A private copy: later edits of the caller's (mutable) params cannot
        # change a built system.
        params = copy.deepcopy(params).validate()
        self._params = params
        self._phantom = phantom
        self._sample = scalar_sampler(phantom)
        self._dt = float(params.period_s)
        ref = params.reference
        self._mode = ref.surface_velocity_mode
        self._position_port = self.DeclareVectorInputPort("ee_position", 3)
        self._velocity_port = self.DeclareVectorInputPort("ee_velocity", 3)
        self._force_port = self.DeclareVectorInputPort("measured_force", 3)
        self._filter_index = self.DeclareDiscreteState(
            surface_velocity_initial_state(ref.surface_velocity_window)
        )
        self.DeclarePeriodicDiscreteUpdateEvent(self._dt, 0.0, self._update)
        self._cache = self.DeclareCacheEntry(
            "references",
            ValueProducer(
                allocate=lambda: AbstractValue.Make(object()), calc=self._calc
            ),
            {self.all_input_ports_ticket(), self.xd_ticket()},
        )
        self._outputs = {}
        for name, size, start in (("target_force", 3, 6), ("references", 13, 0)):
            self._outputs[name] = self.DeclareVectorOutputPort(
                name,
                size,
                self._make_output(start, size),
                {self._cache.ticket()},
            )
        self._last = {}
        for name, size, start in (
            ("force_reference", 3, 0),
            ("force_min", 3, 3),
            ("contact", 4, 9),
        ):
            self._last[name] = (self.DeclareDiscreteState(size), start, size)
            self._outputs[name] = self.DeclareStateOutputPort(name, self._last[name][0])

    def _make_output(self, start: int, size: int):
        def calc(context, output: BasicVector):
            output.SetFromVector(self._cache.Eval(context)[0][start : start + size])

        return calc

    def _evaluate(self, context):
        """(values (13,), new filter state) for the current inputs."""
        p_WP = self._position_port.Eval(context).tolist()
        v_WP = self._velocity_port.Eval(context).tolist()
        f_W = self._force_port.Eval(context).tolist()
        filt = context.get_discrete_state(self._filter_index).value().tolist()
        ref, qp = self._params.reference, self._params.qp
        # A sum of floats is finite iff every term is (inf - inf = nan).
        if not math.isfinite(sum(p_WP) + sum(v_WP) + sum(f_W)):
            values = np.zeros(13)
            values[3:6] = (qp.force_min_N[0], qp.force_min_N[1], -qp.force_max_N[2])
            values[11] = 1.0
            # Restart the filter: the next good sample only records its height
            # (no rate spike across the gap).
            return values, [0.0, *filt[1:]]
        surface_z, dz_dx, dz_dy, kappa, lam = self._sample(p_WP[0], p_WP[1])
        if self._mode == "moving_average":
            new_filt, z_surf_dot = surface_velocity_step(filt, surface_z, self._dt)
        else:
            new_filt = filt
            z_surf_dot = surface_velocity_gradient(dz_dx, dz_dy, v_WP[0], v_WP[1])
        contact = in_contact(f_W[2], ref)
        refs = force_references(
            contact=contact,
            kappa=kappa,
            lam=lam,
            eps_dot=penetration_rate(v_WP[2], z_surf_dot),
            beta=self._phantom.beta,
            ref=ref,
            qp=qp,
        )
        values = [
            *refs.force_ref,
            *refs.force_min,
            *refs.target_force,
            1.0 if contact else 0.0,
            penetration(surface_z, p_WP[2]),
            0.0,
            z_surf_dot,
        ]
        if not math.isfinite(sum(values)):  # E.g. a phantom returning NaN.
            values = [0.0] * 13
            values[3:6] = (qp.force_min_N[0], qp.force_min_N[1], -qp.force_max_N[2])
            values[11] = 1.0
        values = np.array(values)
        return values, new_filt

    def _calc(self, context, value):
        value.set_value(self._evaluate(context))

    def _update(self, context, discrete_state):
        values, new_filt = self._cache.Eval(context)
        discrete_state.get_mutable_vector(self._filter_index).SetFromVector(new_filt)
        for index, start, size in self._last.values():
            discrete_state.set_value(index, values[start : start + size])

    def get_ee_position_input_port(self):
        return self._position_port

    def get_ee_velocity_input_port(self):
        return self._velocity_port

    def get_measured_force_input_port(self):
        return self._force_port

    def get_force_reference_output_port(self):
        return self._outputs["force_reference"]

    def get_force_min_output_port(self):
        return self._outputs["force_min"]

    def get_target_force_output_port(self):
        return self._outputs["target_force"]

    def get_contact_output_port(self):
        return self._outputs["contact"]
