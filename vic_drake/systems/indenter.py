"""The 1-DOF indenter's systems and parameters: tissue, F/T sensor, palpation target.

Each indenter is a body on a vertical prismatic joint of a discrete
:class:`MultibodyPlant`, driven by the plant's implicit joint PD controller
towards a desired state (the position servo of the real Cartesian
controller, with gravity compensated by a feed-forward force). The tissue
pushes back through :class:`HuntCrossleyIndentation`, a thin LeafSystem
calling :func:`vic_drake.tissue.relaxing_hunt_crossley_force` (the law the
full robot's force element uses: Hunt-Crossley whose elastic term relaxes,
by default with :data:`vic_drake.tissue.DEFAULT_RELAXATION`) with each
indenter's surface height, kappa, lambda and beta. :class:`LaggedForceSensor` samples the force the sensor sees
(tissue force minus the inertia of the indenter below it) at 500 Hz, adds
Gaussian noise and delays it by a fixed number of samples, as the real F/T
sensor does. :class:`PalpationTarget` runs the procedure of the real rig:
descend at constant speed until the measured force exceeds a threshold,
record the height, then track a sinusoid a set depth below that height.

Every LeafSystem here is vectorised over n indenters, so many indenters
share one diagram (one joint each; the builder is
:func:`vic_drake.experiments.indenter_bank.MakeIndenterDiagram`) and a whole
campaign costs one simulation. Per-indenter data (surface height, kappa,
lambda, start height) are numeric parameters in the Context.

Force convention: every force here is positive when the body pushes the
indenter up (minus the F/T sensor's z reading).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTACT_THRESHOLD_N
from vic_drake.tissue import (
    DEFAULT_RELAXATION,
    DEFAULT_UPDATE_PERIOD_S,
    RelaxationParams,
    hunt_crossley_force,
    relaxation_input,
    relaxation_step,
    relaxing_hunt_crossley_force,
)


def _check_positive(owner: str, **values) -> None:
    for name, value in values.items():
        if not (np.isfinite(value) and value > 0):
            raise VicDrakeError(
                f"{owner}.{name} must be a finite number > 0, got {value!r}"
            )


@dataclass(frozen=True)
class IndenterParams:
    """The indenter and its position servo.

    The servo gains were identified from the real palpation logs
    (``palpation/test_soft_{1,2,25}hz``, see docs/decisions.md, "Indenter
    servo gains"). The real controller's compliance keeps the penetration
    rate low, which keeps the fit in the regime where the Hunt-Crossley
    force stays compressive.
    """

    moving_mass_kg: float = 2.0  # Mass the servo moves (effective end-effector mass).
    indenter_mass_kg: float = (
        0.081  # Mass below the F/T sensing element (BOTA wrench side).
    )
    servo_stiffness_N_per_m: float = 1000.0  # Position gain of the joint PD servo.
    servo_damping_N_s_per_m: float = 400.0  # Velocity gain of the joint PD servo.
    # Discrete MultibodyPlant step. 2 ms (one step per sensor sample) halves
    # the campaign's simulation time; see docs/decisions.md, "Indenter time step".
    time_step_s: float = 0.001

    def __post_init__(self):
        _check_positive(
            "IndenterParams",
            moving_mass_kg=self.moving_mass_kg,
            servo_stiffness_N_per_m=self.servo_stiffness_N_per_m,
            servo_damping_N_s_per_m=self.servo_damping_N_s_per_m,
            time_step_s=self.time_step_s,
        )
        if not (
            np.isfinite(self.indenter_mass_kg)
            and 0 <= self.indenter_mass_kg <= self.moving_mass_kg
        ):
            raise VicDrakeError(
                "IndenterParams.indenter_mass_kg must be in [0, moving_mass_kg], got "
                f"{self.indenter_mass_kg!r}"
            )


@dataclass(frozen=True)
class SensorParams:
    """The F/T sensor model, from the real palpation logs.

    ``noise_std_N``: the std of the real z force about a Savitzky-Golay
    smoothing in contact (see docs/decisions.md, "Palpation sensor noise").
    ``lag_samples``: the real controller delayed the pose by 28 samples to
    align it with the force (data README), i.e. 56 ms at 500 Hz.
    """

    rate_hz: float = 500.0  # Sampling rate (the UR3e control rate).
    lag_samples: int = 28  # Force delay behind the pose, samples.
    noise_std_N: float = 0.045  # White Gaussian noise on the force, N.
    bias_N: float = 0.0  # Constant tare error, N (real logs: docs/decisions.md).

    def __post_init__(self):
        _check_positive("SensorParams", rate_hz=self.rate_hz)
        if int(self.lag_samples) != self.lag_samples or self.lag_samples < 0:
            raise VicDrakeError(
                f"SensorParams.lag_samples must be an integer >= 0, got {self.lag_samples!r}"
            )
        if not (np.isfinite(self.noise_std_N) and self.noise_std_N >= 0):
            raise VicDrakeError(
                f"SensorParams.noise_std_N must be >= 0, got {self.noise_std_N!r}"
            )
        if not np.isfinite(self.bias_N):
            raise VicDrakeError(
                f"SensorParams.bias_N must be finite, got {self.bias_N!r}"
            )

    @property
    def period_s(self) -> float:
        return 1.0 / self.rate_hz


@dataclass(frozen=True)
class PalpationParams:
    """One sinusoidal palpation, as on the real rig (paper Sec. IV-A)."""

    depth_m: float = 0.015  # Mean target depth below the detected surface.
    amplitude_m: float = 0.008  # Target sinusoid amplitude.
    frequency_hz: float = 2.5  # Target sinusoid frequency.
    duration_s: float = 5.0  # Palpation length after contact.
    start_clearance_m: float = 0.003  # Start height above the true surface.
    approach_speed_m_per_s: float = 0.02  # Descent speed before contact.
    # Measured force that ends the approach, N (the real controller's rule).
    contact_threshold_N: float = CONTACT_THRESHOLD_N
    max_approach_s: float = 1.0  # Give-up time for the approach.
    # Feed the target velocity to the servo. The real Cartesian controller
    # did not (its damping acted on the tip velocity, see IndenterParams).
    velocity_feedforward: bool = False

    def __post_init__(self):
        _check_positive(
            "PalpationParams",
            depth_m=self.depth_m,
            frequency_hz=self.frequency_hz,
            duration_s=self.duration_s,
            approach_speed_m_per_s=self.approach_speed_m_per_s,
            contact_threshold_N=self.contact_threshold_N,
            max_approach_s=self.max_approach_s,
        )
        if not (np.isfinite(self.amplitude_m) and 0 <= self.amplitude_m < self.depth_m):
            raise VicDrakeError(
                "PalpationParams.amplitude_m must be in [0, depth_m) so the target stays "
                f"below the surface, got {self.amplitude_m!r}"
            )
        if not (np.isfinite(self.start_clearance_m) and self.start_clearance_m >= 0):
            raise VicDrakeError(
                "PalpationParams.start_clearance_m must be >= 0, got "
                f"{self.start_clearance_m!r}"
            )


def palpation_target(t, mode, z_start, z_contact, t_contact, params: PalpationParams):
    """Desired height and velocity of every indenter at time t (vectorised).

    Approach (mode 0): descend from z_start at the approach speed. Palpation
    (mode 1): ``z_contact - depth - amplitude sin(2 pi f (t - t_contact))``.
    The desired velocity is the target's derivative with
    ``params.velocity_feedforward``, else zero.

    Returns:
        (z_d, v_d): arrays like ``mode``.
    """
    w = 2 * np.pi * params.frequency_hz
    tau = t - t_contact
    z_app = z_start - params.approach_speed_m_per_s * t
    v_app = np.full_like(z_app, -params.approach_speed_m_per_s)
    z_pal = z_contact - params.depth_m - params.amplitude_m * np.sin(w * tau)
    v_pal = -params.amplitude_m * w * np.cos(w * tau)
    palpating = mode > 0.5
    v_d = np.where(palpating, v_pal, v_app)
    if not params.velocity_feedforward:
        v_d = np.zeros_like(v_d)
    return np.where(palpating, z_pal, z_app), v_d


class HuntCrossleyIndentation(LeafSystem):
    """Hunt-Crossley tissue force on n vertical indenters, optionally relaxing.

    Input ``indenter_state`` (2n: heights q in m, velocities v in m/s).
    Output ``generalized_force`` (n, N, positive up): the force applied to
    each joint, ``relaxing_hunt_crossley_force(s - q, -v, kappa, lambda,
    beta, state, g, clip_tension=True)``
    (:mod:`vic_drake.tissue.relaxation`; plain Hunt-Crossley when every g
    is 0). Numeric parameters (n each): ``surface_z``, ``kappa`` (the
    instantaneous modulus), ``lambda`` (set with :meth:`set_tissue`); and
    the relaxation's fractions g and time constants tau (K each, set with
    :meth:`set_relaxation`). Discrete state (n K, updated every
    ``update_period_s``): the relaxation branch states, m^beta; none when
    built with ``relaxation=None``.
    """

    def __init__(
        self,
        n: int,
        beta: float,
        *,
        relaxation: RelaxationParams | None = DEFAULT_RELAXATION,
        update_period_s: float = DEFAULT_UPDATE_PERIOD_S,
    ):
        """
        Args:
            n: number of indenters.
            beta: Hunt-Crossley exponent.
            relaxation: the tissue's relaxation (its branch count K is fixed
                here; :meth:`set_relaxation` changes the values, g = 0 gives
                plain HC); None: plain HC without state.
            update_period_s: period of the branch-state update, s.
        """
        super().__init__()
        _check_positive(
            "HuntCrossleyIndentation", beta=beta, update_period_s=update_period_s
        )
        self._n = int(n)
        self._beta = float(beta)
        self._period = float(update_period_s)
        self._k = 0 if relaxation is None else relaxation.n_branches
        self._surface_index = self.DeclareNumericParameter(BasicVector(np.zeros(n)))
        self._kappa_index = self.DeclareNumericParameter(BasicVector(np.ones(n)))
        self._lam_index = self.DeclareNumericParameter(BasicVector(np.zeros(n)))
        self._state_port = self.DeclareVectorInputPort("indenter_state", 2 * n)
        self._branches = None
        if self._k:
            self._g_index = self.DeclareNumericParameter(
                BasicVector(np.asarray(relaxation.fractions))
            )
            self._tau_index = self.DeclareNumericParameter(
                BasicVector(np.asarray(relaxation.time_constants_s))
            )
            self._branches = self.DeclareDiscreteState(np.zeros(n * self._k))
            self.DeclarePeriodicDiscreteUpdateEvent(self._period, 0.0, self._update)
        self._force_port = self.DeclareVectorOutputPort(
            "generalized_force", n, self._calc_force
        )

    def get_indenter_state_input_port(self):
        return self._state_port

    def get_generalized_force_output_port(self):
        return self._force_port

    @property
    def beta(self) -> float:
        return self._beta

    @property
    def n_branches(self) -> int:
        """K, the relaxation branches per indenter (0: plain HC, no state)."""
        return self._k

    def set_tissue(self, context, *, surface_z, kappa, lam) -> None:
        """Writes the tissue under each indenter into this system's context.

        ``kappa`` is the instantaneous modulus (the relaxed one is
        ``g_inf kappa``, see :mod:`vic_drake.tissue.relaxation`).
        """
        for index, value in (
            (self._surface_index, surface_z),
            (self._kappa_index, kappa),
            (self._lam_index, lam),
        ):
            context.get_mutable_numeric_parameter(index).SetFromVector(
                np.broadcast_to(np.asarray(value, float), (self._n,))
            )

    def set_relaxation(self, context, relaxation: RelaxationParams | None) -> None:
        """Sets the relaxation in ``context`` (None: plain HC, g = 0).

        Raises:
            VicDrakeError: ``relaxation`` has a branch count other than the
                one this system was built with.
        """
        if relaxation is None:
            if self._k:
                context.get_mutable_numeric_parameter(self._g_index).SetZero()
            return
        if relaxation.n_branches != self._k:
            raise VicDrakeError(
                f"HuntCrossleyIndentation was built with {self._k} relaxation "
                f"branches; got a relaxation with {relaxation.n_branches}"
            )
        if self._k:
            context.get_mutable_numeric_parameter(self._g_index).SetFromVector(
                np.asarray(relaxation.fractions)
            )
            context.get_mutable_numeric_parameter(self._tau_index).SetFromVector(
                np.asarray(relaxation.time_constants_s)
            )

    def _inputs(self, context):
        x = self._state_port.Eval(context)
        s = context.get_numeric_parameter(self._surface_index).get_value()
        return s - x[: self._n], -x[self._n :]

    def _update(self, context, discrete_state):
        eps, _ = self._inputs(context)
        tau = context.get_numeric_parameter(self._tau_index).get_value()
        state = context.get_discrete_state(self._branches).get_value()
        new = relaxation_step(
            state.reshape(self._n, self._k),
            relaxation_input(eps, self._beta),
            self._period,
            tau,
        )
        discrete_state.get_mutable_vector(self._branches).SetFromVector(new.ravel())

    def _calc_force(self, context, output):
        eps, eps_dot = self._inputs(context)
        kappa = context.get_numeric_parameter(self._kappa_index).get_value()
        lam = context.get_numeric_parameter(self._lam_index).get_value()
        if self._k:
            state = (
                context.get_discrete_state(self._branches)
                .get_value()
                .reshape(self._n, self._k)
            )
            g = context.get_numeric_parameter(self._g_index).get_value()
            force = relaxing_hunt_crossley_force(
                eps, eps_dot, kappa, lam, self._beta, state, g, clip_tension=True
            )
        else:
            force = hunt_crossley_force(
                eps, eps_dot, kappa, lam, self._beta, clip_tension=True
            )
        output.SetFromVector(force)


def sensed_force(
    tissue_force, acceleration, noise, *, indenter_mass_kg, noise_std_N, bias_N
):
    """What the tared F/T sensor reads (positive up): F - m_I a + noise + bias."""
    return tissue_force - indenter_mass_kg * acceleration + noise_std_N * noise + bias_N


class LaggedForceSensor(LeafSystem):
    """A tared F/T sensor on n indenters: sampled, noisy and delayed.

    Inputs: ``tissue_force`` (n, N), ``acceleration`` (n, m/s^2),
    ``noise`` (n, unit Gaussian samples, e.g. from a RandomSource).
    Output: ``measured_force`` (n, N, positive up), the reading of
    ``lag_samples`` periods ago. The delay line is discrete state.
    """

    def __init__(self, n: int, params: SensorParams, *, indenter_mass_kg: float):
        super().__init__()
        self._n = int(n)
        self._params = params
        self._mass = float(indenter_mass_kg)
        self._depth = int(params.lag_samples) + 1
        self._tissue_port = self.DeclareVectorInputPort("tissue_force", n)
        self._acc_port = self.DeclareVectorInputPort("acceleration", n)
        self._noise_port = self.DeclareVectorInputPort("noise", n)
        # Row k of the (depth, n) delay line is the reading of k periods ago.
        self._buffer = self.DeclareDiscreteState(self._depth * n)
        self.DeclarePeriodicDiscreteUpdateEvent(params.period_s, 0.0, self._update)
        self._output_port = self.DeclareVectorOutputPort(
            "measured_force",
            n,
            self._calc_output,
            {self.discrete_state_ticket(self._buffer)},
        )

    def get_measured_force_output_port(self):
        return self._output_port

    def _update(self, context, discrete_state):
        buffer = (
            context.get_discrete_state(self._buffer)
            .get_value()
            .reshape(self._depth, self._n)
        )
        reading = sensed_force(
            self._tissue_port.Eval(context),
            self._acc_port.Eval(context),
            self._noise_port.Eval(context),
            indenter_mass_kg=self._mass,
            noise_std_N=self._params.noise_std_N,
            bias_N=self._params.bias_N,
        )
        shifted = np.vstack([reading[None, :], buffer[:-1]])
        discrete_state.get_mutable_vector(self._buffer).SetFromVector(shifted.ravel())

    def _calc_output(self, context, output):
        buffer = context.get_discrete_state(self._buffer).get_value()
        output.SetFromVector(buffer[-self._n :])


class PalpationTarget(LeafSystem):
    """The palpation procedure of the real rig, for n indenters.

    Input ``measured_force`` (n, N) and ``indenter_state`` (2n). Discrete
    state (updated at the sensor rate): per indenter the mode (0 approach,
    1 palpation), the height and the time at which the measured force first
    exceeded the contact threshold. Output ``desired_state`` (2n: heights,
    velocities), see :func:`palpation_target`. Numeric parameter
    ``start_z`` (n): the height each approach starts from.
    """

    def __init__(self, n: int, params: PalpationParams, *, period_s: float):
        super().__init__()
        self._n = int(n)
        self._params = params
        self._start_index = self.DeclareNumericParameter(BasicVector(np.zeros(n)))
        self._force_port = self.DeclareVectorInputPort("measured_force", n)
        self._state_port = self.DeclareVectorInputPort("indenter_state", 2 * n)
        self._mode = self.DeclareDiscreteState(np.zeros(3 * n))
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._update)
        self._desired_port = self.DeclareVectorOutputPort(
            "desired_state",
            2 * n,
            self._calc_desired,
            {
                self.time_ticket(),
                self.discrete_state_ticket(self._mode),
                self.all_parameters_ticket(),
            },
        )
        self._contact_port = self.DeclareStateOutputPort("contact", self._mode)

    def get_desired_state_output_port(self):
        return self._desired_port

    def get_contact_output_port(self):
        """(3n): mode, contact height (m), contact time (s) per indenter."""
        return self._contact_port

    def set_start_z(self, context, start_z) -> None:
        context.get_mutable_numeric_parameter(self._start_index).SetFromVector(
            np.broadcast_to(np.asarray(start_z, float), (self._n,))
        )

    def _update(self, context, discrete_state):
        n = self._n
        state = context.get_discrete_state(self._mode).get_value().reshape(3, n).copy()
        mode, z_c, t_c = state
        force = self._force_port.Eval(context)
        q = self._state_port.Eval(context)[:n]
        t = context.get_time()
        hit = (mode < 0.5) & (force > self._params.contact_threshold_N)
        mode[hit], z_c[hit], t_c[hit] = 1.0, q[hit], t
        discrete_state.get_mutable_vector(self._mode).SetFromVector(state.ravel())

    def _calc_desired(self, context, output):
        n = self._n
        mode, z_c, t_c = (
            context.get_discrete_state(self._mode).get_value().reshape(3, n)
        )
        z0 = context.get_numeric_parameter(self._start_index).get_value()
        z_d, v_d = palpation_target(
            context.get_time(), mode, z0, z_c, t_c, self._params
        )
        output.SetFromVector(np.concatenate([z_d, v_d]))


__all__ = [
    "HuntCrossleyIndentation",
    "IndenterParams",
    "LaggedForceSensor",
    "PalpationParams",
    "PalpationTarget",
    "SensorParams",
    "palpation_target",
    "sensed_force",
]
