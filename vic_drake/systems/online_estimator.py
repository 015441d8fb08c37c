"""OnlineEstimatorSystem: the RLS or EKF tissue estimator as a LeafSystem.

A thin adapter over :mod:`vic_drake.estimation.online`: every period it
reads the probe's position and velocity and the F/T force (one
"measurement" vector, the reference system's) and (optionally) the surface
height, calls the pure step function of the chosen method and
stores the filter state and the estimate in discrete state; the outputs
publish the estimate from state (the values of the last tick).
"""

from __future__ import annotations

import copy
import math

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online import (
    OUTPUT_FIELDS,
    OnlineEstimatorParams,
    estimator_functions,
)
from vic_drake.systems.signals import (
    MEASURED_FORCE,
    MEASURED_POSITION,
    MEASURED_VELOCITY,
    MEASUREMENT_SIZE,
    REF_FORCE_MIN,
    REF_FORCE_REFERENCE,
    REFERENCE_TICK_SIZE,
)

#: Where the estimator's scalars sit in the "measurement" vector: the probe
#: tip's x, y, z, its z velocity and the force's z.
_X, _Y, _Z = range(MEASURED_POSITION.start, MEASURED_POSITION.stop)
_VZ = MEASURED_VELOCITY.start + 2
_FZ = MEASURED_FORCE.start + 2

#: K_z counts as at its bound from this fraction below it.
SATURATION_REL_TOL = 1e-3
#: F_ref,z and F_min,z in the "references" input.
_F_REF_Z = REF_FORCE_REFERENCE.start + 2
_F_MIN_Z = REF_FORCE_MIN.start + 2


def at_flat_force_bound(
    force_ref_z_N: float, force_min_z_N: float, bound_z_N: float
) -> bool:
    """Whether the controller holds the z force at a bound that does not
    follow the dither: the reference is capped by F_min,z (sensor
    convention: below it) while F_min,z is at the scenario's ``bound_z_N``
    (the dither lowers it only in its lower half-cycle)."""
    return force_ref_z_N < force_min_z_N <= bound_z_N


#: Index of each field in the "estimate" output.
ESTIMATE_SIZE = len(OUTPUT_FIELDS)
_I = {name: i for i, name in enumerate(OUTPUT_FIELDS)}


class OnlineEstimatorSystem(LeafSystem):
    """Online kappa, lambda (and surface) estimate from force and motion.

    Input ports:
        measurement (9, ``signals.MEASUREMENT_SIZE``): what a tick reads,
            the layout of ForceReferenceSystem's input (the ``MEASURED_*``
            slices of :mod:`vic_drake.systems.signals`): probe tip p_WP, m;
            v_WP, m/s; F/T force in W, N, sensor convention (negative z =
            pressing; the tissue force is minus its z).
        surface_z (1): tissue surface height under the probe, m (only with
            ``surface_input=True``; NaN = unknown). Without it the surface
            is latched at first contact (and corrected by the EKF when its
            surface state is on), or, with ``surface_map`` (a Phantom), read
            from the map under the probe.
        stiffness (3): the controller's stiffness K, N/m (only with
            ``stiffness_max_z``): the slope fit softens its held kappa while
            K_z is at ``stiffness_max_z``
            (:mod:`vic_drake.estimation.online.slope`).
        references (``signals.REFERENCE_TICK_SIZE``): the head of the force
            reference system's "tick" output, its "references" first, as the
            QP reads it (only with ``force_min_z``): the slope fit's
            "tracker" mode leaves out the samples at which F_ref,z is capped
            by F_min,z while F_min,z is at ``force_min_z``
            (:func:`at_flat_force_bound`).

    ``dither_hz`` (only with the estimator's ``surface_from_slope``): the
    frequency of the controller's penetration dither, Hz, whose phase is
    2 pi dither_hz t on the same clock: the slope fit's instrument
    (``OnlineEstimatorParams.slope_instrument``;
    :mod:`vic_drake.estimation.online.slope_instrument`).

    Output ports (state: the last tick's estimate):
        estimate (7): :data:`vic_drake.estimation.online.OUTPUT_FIELDS`.
        kappa_hat (1), lambda_hat (1), variances (2: kappa, lambda),
        valid (1), surface_z_hat (1).

    A non-finite input leaves the estimate unchanged (never a NaN
    estimate); ``valid`` is 0 on that tick.
    """

    def __init__(
        self,
        params: OnlineEstimatorParams,
        *,
        period_s: float,
        surface_input: bool = True,
        surface_map=None,
        stiffness_max_z: float | None = None,
        force_min_z: float | None = None,
        dither_hz: float | None = None,
    ):
        super().__init__()
        if not isinstance(params, OnlineEstimatorParams):
            raise VicDrakeError(
                f"OnlineEstimatorSystem needs OnlineEstimatorParams; got {params!r}"
            )
        if not (math.isfinite(period_s) and period_s > 0.0):
            raise VicDrakeError(f"period_s must be > 0; got {period_s!r}")
        self._params = copy.deepcopy(params).validate()
        init, self._step = estimator_functions(self._params)
        state0 = init(self._params)
        _, est0 = self._step(
            state0, 0.0, 0.0, 0.0, math.nan, math.nan, self._params
        )  # A fault sample: the prior's outputs, state unchanged but the count.
        self._measurement_port = self.DeclareVectorInputPort(
            "measurement", MEASUREMENT_SIZE
        )
        if surface_input and surface_map is not None:
            raise VicDrakeError("give either surface_input or surface_map, not both")
        self._surface_port = (
            self.DeclareVectorInputPort("surface_z", 1) if surface_input else None
        )
        # The map's surface under the probe (a Phantom's point lookup).
        self._surface_lookup = (
            None if surface_map is None else surface_map.point_lookup()
        )
        for name, value in (
            ("stiffness_max_z", stiffness_max_z),
            ("force_min_z", force_min_z),
            ("dither_hz", dither_hz),
        ):
            if value is not None and not self._params.surface_from_slope:
                raise VicDrakeError(
                    f"{name} is for the estimator's surface_from_slope; it is off"
                )
        if dither_hz is not None and not (math.isfinite(dither_hz) and dither_hz > 0.0):
            raise VicDrakeError(f"dither_hz must be > 0; got {dither_hz!r}")
        self._dither_hz = 0.0 if dither_hz is None else float(dither_hz)
        self._stiffness_port = None
        if stiffness_max_z is not None:
            if not (math.isfinite(stiffness_max_z) and stiffness_max_z > 0.0):
                raise VicDrakeError(
                    f"stiffness_max_z must be > 0; got {stiffness_max_z!r}"
                )
            self._stiffness_port = self.DeclareVectorInputPort("stiffness", 3)
            self._k_saturated = stiffness_max_z * (1.0 - SATURATION_REL_TOL)
        self._references_port = None
        if force_min_z is not None:
            if not (math.isfinite(force_min_z) and force_min_z < 0.0):
                raise VicDrakeError(
                    f"force_min_z must be < 0 (sensor convention); got {force_min_z!r}"
                )
            self._references_port = self.DeclareVectorInputPort(
                "references", REFERENCE_TICK_SIZE
            )
            self._force_min_z = force_min_z
        # Whether the step takes the slope fit's controller inputs (decided
        # once: the tick then tests one flag).
        self._fit_inputs = (
            self._stiffness_port is not None
            or self._references_port is not None
            or self._dither_hz != 0.0
        )
        self._filter = self.DeclareDiscreteState(np.asarray(state0, float))
        self._estimate = self.DeclareDiscreteState(np.asarray(est0, float))
        self.DeclarePeriodicDiscreteUpdateEvent(float(period_s), 0.0, self._update)
        self._ports = {
            "estimate": self.DeclareStateOutputPort("estimate", self._estimate)
        }
        for name, part in (
            ("kappa_hat", [_I["kappa_hat"]]),
            ("lambda_hat", [_I["lambda_hat"]]),
            ("variances", [_I["kappa_var"], _I["lambda_var"]]),
            ("valid", [_I["valid"]]),
            ("surface_z_hat", [_I["surface_z_m"]]),
        ):
            self._ports[name] = self.DeclareVectorOutputPort(
                name, len(part), self._make_output(part), {self.xd_ticket()}
            )

    def _make_output(self, part):
        def calc(context, output: BasicVector):
            values = context.get_discrete_state(self._estimate).get_value()
            output.SetFromVector(values[part])

        return calc

    def _update(self, context, discrete_state):
        m = self._measurement_port.Eval(context).tolist()
        if self._surface_port is not None:
            s = float(self._surface_port.Eval(context)[0])
        elif self._surface_lookup is not None and math.isfinite(m[_X] + m[_Y]):
            s = self._surface_lookup(m[_X], m[_Y])[0]
        else:
            s = math.nan
        # Drake fills discrete_state with the current state before calling
        # this handler: the filter state is read from it and written in place.
        state = discrete_state.value(self._filter).tolist()
        args = (state, context.get_time(), m[_Z], m[_VZ], -m[_FZ], s, self._params)
        if not self._fit_inputs:
            state, est = self._step(*args)
        else:
            saturated = at_bound = False
            if self._stiffness_port is not None:
                k_z = float(self._stiffness_port.Eval(context)[2])
                saturated = k_z >= self._k_saturated
            if self._references_port is not None:
                r = self._references_port.Eval(context)
                at_bound = at_flat_force_bound(
                    float(r[_F_REF_Z]), float(r[_F_MIN_Z]), self._force_min_z
                )
            state, est = self._step(*args, saturated, at_bound, self._dither_hz)
        discrete_state.get_mutable_value(self._filter)[:] = state
        discrete_state.get_mutable_value(self._estimate)[:] = est

    def get_measurement_input_port(self):
        return self._measurement_port

    def get_stiffness_input_port(self):
        """The "stiffness" input (None without ``stiffness_max_z``)."""
        return self._stiffness_port

    def get_references_input_port(self):
        """The "references" input (None without ``force_min_z``)."""
        return self._references_port

    def get_estimate_output_port(self):
        return self._ports["estimate"]

    def get_kappa_output_port(self):
        return self._ports["kappa_hat"]

    def get_lambda_output_port(self):
        return self._ports["lambda_hat"]

    def get_variances_output_port(self):
        return self._ports["variances"]

    def get_valid_output_port(self):
        return self._ports["valid"]

    def get_surface_output_port(self):
        return self._ports["surface_z_hat"]


class RlsEstimatorSystem(OnlineEstimatorSystem):
    """:class:`OnlineEstimatorSystem` with the recursive least squares."""

    def __init__(self, params: OnlineEstimatorParams, **kwargs):
        params = copy.deepcopy(params)
        params.method = "rls"
        super().__init__(params, **kwargs)


class EkfEstimatorSystem(OnlineEstimatorSystem):
    """:class:`OnlineEstimatorSystem` with the EKF."""

    def __init__(self, params: OnlineEstimatorParams, **kwargs):
        params = copy.deepcopy(params)
        params.method = "ekf"
        super().__init__(params, **kwargs)


__all__ = [
    "ESTIMATE_SIZE",
    "SATURATION_REL_TOL",
    "EkfEstimatorSystem",
    "OnlineEstimatorSystem",
    "RlsEstimatorSystem",
]
