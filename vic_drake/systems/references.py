"""ForceReferenceSystem: contact, penetration rate and force references.

A thin LeafSystem over :mod:`vic_drake.control.references`. The references
are cheap algebra on the current measurement, so they are computed once per
tick in the "tick" output port, with direct feedthrough ("references" and
"target_force" are slices of it: the real controller computed them from the
same sample as its QP, and the QP and FDCC read them within the same tick).
The periodic discrete update at the controller rate advances the
surface-velocity filter and stores the tick's values, which the
"force_reference", "force_min" and "contact" ports publish from state: what
the QP used at the last tick (loggers read them after the tick's update
without recomputing). Only CF
has a nonzero target force; for the other controllers "target_force" is a
constant zero, computed once. The packed "references" and "contact" layouts
are in :mod:`vic_drake.systems.signals`.
"""

from __future__ import annotations

import copy
import math

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

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
from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online import OUTPUT_FIELDS as ESTIMATE_FIELDS
from vic_drake.systems.signals import (
    MEASURED_FORCE,
    MEASURED_POSITION,
    MEASURED_VELOCITY,
    MEASUREMENT_SIZE,
    REF_CONTACT,
    REF_FAULT,
    REF_FORCE_MIN,
    REF_FORCE_REFERENCE,
    REF_IN_CONTACT,
    REF_PENETRATION,
    REF_SURFACE_VELOCITY,
    REF_TARGET_FORCE,
    REFERENCES_SIZE,
    TICK_RECORD_SIZE,
)
from vic_drake.tissue.phantom import Phantom

#: The map sample of a faulty tick (no lookup was made).
_NO_SAMPLE = (math.nan, math.nan)
#: The "tick" vector (one per tick): the references, the tick record, the new
#: surface-velocity filter state.
_REFERENCES = slice(0, REFERENCES_SIZE)
_RECORD = slice(REFERENCES_SIZE, REFERENCES_SIZE + TICK_RECORD_SIZE)
_FILTER_START = _RECORD.stop
_ESTIMATE_KAPPA = ESTIMATE_FIELDS.index("kappa_hat")
_ESTIMATE_LAMBDA = ESTIMATE_FIELDS.index("lambda_hat")
_ESTIMATE_SURFACE_Z = ESTIMATE_FIELDS.index("surface_z_m")


def _array(values: list) -> np.ndarray:
    """The floats of a list as a float array."""
    return np.fromiter(values, float, len(values))


class ForceReferenceSystem(LeafSystem):
    """Force references of the selected controller (CS, CF, VS-CF, VS-VF).

    Input port:
        measurement (9): probe tip p_WP (m), its velocity v_WP (m/s) and the
            F/T force in W (N, sensor convention), one vector (layout:
            ``MEASUREMENT_SIZE`` and the ``MEASURED_*`` slices of
            :mod:`vic_drake.systems.signals`; the controller Diagram builds
            it from its three inputs with a C++ Multiplexer).

    Output ports (direct feedthrough of the current inputs):
        target_force (3): force the FDCC stage tracks, N (CF only; a
            constant zero, without feedthrough, for CS, VS-CF and VS-VF).
        references (13): F_ref, F_min, target force, contact (layout
            :data:`vic_drake.systems.signals.REFERENCES_SIZE` and the
            ``REF_*`` slices), read by StiffnessQpSystem in one port
            evaluation.
        tick (13 + 11 + filter size): the references, then the tick
            record (as "tick_record"), then the new surface-velocity
            filter state: what the update stores. The controller Diagram
            splits it with a C++ Demultiplexer for the QP.
    Output ports (state: the values of the last tick):
        force_reference (3): F_ref, N (sensor convention).
        force_min (3): F_min, N.
        contact (4): :data:`vic_drake.systems.signals.CONTACT_FIELDS`
            (in_contact, penetration_m, fault, surface_velocity_m_per_s).
        tick_record (11): :data:`vic_drake.systems.signals.TICK_RECORD_FIELDS`,
            the position, velocity and force the tick read and the map's
            kappa and lambda its lookup returned (NaN on a faulty tick): what
            the real controller logged of its tick (the rig log layout).

    State: the surface-velocity filter and the last tick's F_ref, F_min,
    contact (discrete, updated every period).
    A non-finite input gives F_ref = 0, F_min = (F_min,x, F_min,y,
    -F_max,z), target 0, in_contact 0 and fault 1 (never a NaN output).
    """

    def __init__(
        self,
        params: ControllerParams,
        *,
        phantom: Phantom | None,
        stiffness_source: str = "map",
        beta: float | None = None,
    ):
        """``stiffness_source="online"``: kappa, lam and the surface come from
        the "tissue.estimate" input (an OnlineEstimatorSystem's "estimate"
        port) instead of the phantom (which may then be None); ``beta`` is
        the estimator's exponent. A NaN estimated surface gives a zero
        surface rate.
        """
        super().__init__()
        # A private copy: later edits of the caller's (mutable) params cannot
        # change a built system.
        params = copy.deepcopy(params).validate()
        self._params = params
        self._phantom = phantom
        self._online = stiffness_source == "online"
        if stiffness_source not in ("map", "online"):
            raise VicDrakeError(
                f"stiffness_source must be 'map' or 'online'; got {stiffness_source!r}"
            )
        if self._online:
            if beta is None or not (0.0 < float(beta) <= 3.0):
                raise VicDrakeError(
                    f"online references need beta in (0, 3]; got {beta!r}"
                )
            if params.reference.surface_velocity_mode != "moving_average":
                raise VicDrakeError(
                    "online references need reference.surface_velocity_mode "
                    "'moving_average' (no map gradient without a map); got "
                    f"{params.reference.surface_velocity_mode!r}"
                )
            self._beta = float(beta)
            self._sample = None
        else:
            if phantom is None:
                raise VicDrakeError("map references need a phantom")
            self._beta = phantom.beta
            self._sample = scalar_sampler(phantom)
        self._dt = float(params.period_s)
        ref = params.reference
        self._moving_average = ref.surface_velocity_mode == "moving_average"
        self._measurement_port = self.DeclareVectorInputPort(
            "measurement", MEASUREMENT_SIZE
        )
        self._estimate_port = (
            self.DeclareVectorInputPort("tissue.estimate", len(ESTIMATE_FIELDS))
            if self._online
            else None
        )
        filter_state = surface_velocity_initial_state(ref.surface_velocity_window)
        self._filter_index = self.DeclareDiscreteState(filter_state)
        self.DeclarePeriodicDiscreteUpdateEvent(self._dt, 0.0, self._update)
        # The tick's values, one vector (see _evaluate): a vector output port,
        # so that the controller Diagram can hand its references to the QP
        # through a C++ Demultiplexer (no Python call for the QP's read). With
        # VS-VF's penetration dither they depend on the time too.
        self._dither = ref.penetration_dither_m > 0.0
        tickets = {
            self.all_input_ports_ticket(),
            self.discrete_state_ticket(self._filter_index),
        }
        if self._dither:
            tickets.add(self.time_ticket())
        self._tick_size = _FILTER_START + len(filter_state)
        self._tick_port = tick_port = self.DeclareVectorOutputPort(
            "tick", self._tick_size, self._calc, tickets
        )
        self._outputs = {"tick": tick_port}
        if ref.controller == "cf":
            self._outputs["target_force"] = self.DeclareVectorOutputPort(
                "target_force",
                3,
                self._calc_target_force,
                {tick_port.cache_entry().ticket()},
            )
        else:  # Zero at every tick, faulty or not.
            self._outputs["target_force"] = self.DeclareVectorOutputPort(
                "target_force",
                3,
                lambda context, output: output.SetZero(),
                {self.nothing_ticket()},
            )
        self._outputs["references"] = self.DeclareVectorOutputPort(
            "references",
            REFERENCES_SIZE,
            self._calc_references,
            {tick_port.cache_entry().ticket()},
        )
        # (state group, its slice of the tick vector): every group, all
        # written by the update.
        self._state_parts = [
            (
                self._filter_index,
                slice(_FILTER_START, _FILTER_START + len(filter_state)),
            )
        ]
        for name, part in (
            ("force_reference", REF_FORCE_REFERENCE),
            ("force_min", REF_FORCE_MIN),
            ("contact", REF_CONTACT),
            ("tick_record", _RECORD),
        ):
            initial = np.nan if name == "tick_record" else 0.0
            index = self.DeclareDiscreteState(np.full(part.stop - part.start, initial))
            self._state_parts.append((index, part))
            self._outputs[name] = self.DeclareStateOutputPort(name, index)
        # Scratch for the update: filled through numpy views of its groups,
        # then copied into the update's result with one SetFrom. Only the
        # update uses it, and it overwrites all of it each time.
        self._scratch = self.AllocateDiscreteVariables()
        self._scratch_views = [
            (self._scratch.get_mutable_value(index), part)
            for index, part in self._state_parts
        ]
        # The references of a faulty tick: zero F_ref, F_min,z = -F_max,z,
        # fault.
        qp = params.qp
        safe = [0.0] * REFERENCES_SIZE
        safe[REF_FORCE_MIN] = (qp.force_min_N[0], qp.force_min_N[1], -qp.force_max_N[2])
        safe[REF_FAULT] = 1.0
        self._safe_values = safe

    def _calc_references(self, context, output: BasicVector):
        output.set_value(self._tick_port.Eval(context)[_REFERENCES])

    def _calc_target_force(self, context, output: BasicVector):
        output.set_value(self._tick_port.Eval(context)[REF_TARGET_FORCE])

    def _evaluate(self, context) -> np.ndarray:
        """The tick now, as one array: the references (``_REFERENCES``), the
        tick record (``_RECORD``), then the new filter state."""
        measured = self._measurement_port.Eval(context).tolist()
        p_WP = measured[MEASURED_POSITION]
        v_WP = measured[MEASURED_VELOCITY]
        f_W = measured[MEASURED_FORCE]
        filt = context.get_discrete_state(self._filter_index).value().tolist()
        # A sum of floats is finite iff every term is (inf - inf = nan).
        if not math.isfinite(sum(measured)):
            # Restart the filter: the next good sample only records its height
            # (no rate spike across the gap).
            filt[0] = 0.0
            return _array([*self._safe_values, *p_WP, *v_WP, *f_W, *_NO_SAMPLE, *filt])
        if self._online:
            est = self._estimate_port.Eval(context).tolist()
            kappa = est[_ESTIMATE_KAPPA]
            lam = est[_ESTIMATE_LAMBDA]
            surface_z = est[_ESTIMATE_SURFACE_Z]
            dz_dx = dz_dy = 0.0
        else:
            surface_z, dz_dx, dz_dy, kappa, lam = self._sample(p_WP[0], p_WP[1])
        restart = False
        if not math.isfinite(surface_z):  # Online, before contact: no surface.
            # Zero penetration and rate; restart the filter so that the
            # surface latched at contact is not read as a jump.
            filt[0] = 0.0
            surface_z, dz_dx, dz_dy = p_WP[2], 0.0, 0.0
            restart = True
        if not self._moving_average:
            z_surf_dot = surface_velocity_gradient(dz_dx, dz_dy, v_WP[0], v_WP[1])
        elif restart:
            z_surf_dot = 0.0
        else:
            filt, z_surf_dot = surface_velocity_step(filt, surface_z, self._dt)
        ref = self._params.reference
        contact = in_contact(f_W[2], ref)
        f_ref, f_min, target = force_references(
            contact=contact,
            kappa=kappa,
            lam=lam,
            eps_dot=penetration_rate(v_WP[2], z_surf_dot),
            beta=self._beta,
            ref=ref,
            qp=self._params.qp,
            t_s=context.get_time() if self._dither else 0.0,
        )
        values = [0.0] * REFERENCES_SIZE  # A list: cheaper than numpy per element.
        values[REF_FORCE_REFERENCE] = f_ref
        values[REF_FORCE_MIN] = f_min
        values[REF_TARGET_FORCE] = target
        values[REF_IN_CONTACT] = 1.0 if contact else 0.0
        values[REF_PENETRATION] = penetration(surface_z, p_WP[2])
        values[REF_SURFACE_VELOCITY] = z_surf_dot  # REF_FAULT stays 0.
        if not math.isfinite(sum(values)):  # E.g. a phantom returning NaN.
            return _array([*self._safe_values, *p_WP, *v_WP, *f_W, *_NO_SAMPLE, *filt])
        return _array([*values, *p_WP, *v_WP, *f_W, kappa, lam, *filt])

    def _calc(self, context, output: BasicVector):
        output.set_value(self._evaluate(context))

    def _update(self, context, discrete_state):
        tick = self._tick_port.Eval(context)
        for view, part in self._scratch_views:
            view[:] = tick[part]
        discrete_state.SetFrom(self._scratch)

    def get_measurement_input_port(self):
        return self._measurement_port

    def get_force_reference_output_port(self):
        return self._outputs["force_reference"]

    def get_force_min_output_port(self):
        return self._outputs["force_min"]

    def get_target_force_output_port(self):
        return self._outputs["target_force"]

    def get_contact_output_port(self):
        return self._outputs["contact"]

    def get_tick_record_output_port(self):
        return self._outputs["tick_record"]

    def get_references_output_port(self):
        return self._outputs["references"]

    def get_tick_output_port(self):
        return self._outputs["tick"]
