"""The Hunt-Crossley tissue force element acting on the probe tip.

The tissue's push-back on the indenter is the paper's Hunt-Crossley law
(eq. 1), evaluated from the phantom map at the tip's (x, y) -- the one place
tissue force comes from. Drake's own contact between the indenter and the
phantom is filtered out in the station, so the force is counted once.

Geometry and signs (all in the world frame W = the rig's ``base_link``):

- The probe point T is the indenter's lowest point (the bottom of its 2 cm
  spherical tip), the rig's ``probe`` frame. The penetration is measured
  vertically, as the real controller did (``map z + 0.0025 - z``):
  ``eps = s(x - x_P, y - y_P) + z_P - z_T``, with s the phantom's surface
  height in its own (map) frame and p_WP = (x_P, y_P, z_P) the phantom
  body's translation (its lift). The sphere's growing contact area is what
  the fitted exponent beta accounts for.
- Its rate, by the chain rule on that expression (the phantom translates
  only, with velocity v_WP):
  ``eps_dot = s_x (xdot_T - xdot_P) + s_y (ydot_T - ydot_P) + zdot_P - zdot_T``.
- The force magnitude is ``hunt_crossley_force(eps, eps_dot, kappa, lam,
  beta)`` minus the relaxed part ``kappa sum_i g_i s_i`` of an optional
  relaxation (:mod:`vic_drake.tissue.relaxation`; the branch states s_i are
  the element's discrete state, updated each tick), clipped at zero (zero
  out of contact, never pulling): the
  vertical component of the force on the indenter body at T; the equal and
  opposite force acts on the phantom body at the same point. The map's kappa
  and lambda were fitted to vertical indentations, so the law gives the
  vertical force, as in the paper's 1-D model. Two horizontal terms, on in
  the station's defaults (``StationParams.tissue_force_along_normal``,
  ``tissue_friction_coefficient``), add what the real scans' lateral sensor
  forces show (:func:`vic_drake.analysis.identification.estimate_tissue_friction`; see
  docs/decisions.md, "Lateral tissue forces"): the force tilted along the
  surface normal, ``F (-dz/dx, -dz/dy, 1)``, and a regularised sliding
  friction ``-mu F v_t / sqrt(|v_t|^2 + v_s^2)``. The element's own
  defaults are the paper's vertical model.

  Note on the real logs' sensor x, y columns: they are the external force in
  the sensor frame S (tool pointing down: x_S = x_W, y_S = -y_W, z_S =
  -z_W); :func:`vic_drake.analysis.columns.real_to_canonical` turns them into the
  canonical reading, minus the external force in W, by negating x.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialForce, SpatialVelocity
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.framework import LeafSystem, ValueProducer

from vic_drake.errors import VicDrakeError
from vic_drake.systems.body_reader import PlantBodyReader, port_or_error
from vic_drake.tissue import (
    DEFAULT_UPDATE_PERIOD_S,
    Phantom,
    RelaxationParams,
)
from vic_drake.tissue.tip_contact import (
    TipContact,
    contact_terms,
    force_W_of_terms,
    tip_contact,
)

#: Elements of the element's ``tissue.sample`` output (its state after each
#: tick): the tip's kinematics, the force on it, the contact and the map
#: there, and the point of the reaction in the phantom body's frame.
SAMPLE_FIELDS = (
    "x_m", "y_m", "z_m",
    "vx_m_per_s", "vy_m_per_s", "vz_m_per_s",
    "force_x_N", "force_y_N", "force_z_N",
    "penetration_m", "penetration_rate_m_per_s", "surface_z_m",
    "kappa", "lam",
    "reaction_x_m", "reaction_y_m", "reaction_z_m",
)  # fmt: skip
_SAMPLE_SIZE = len(SAMPLE_FIELDS)


class TissueForceElement(LeafSystem):
    """Applies the Hunt-Crossley tissue force at the probe tip (see module doc).

    Input ports, without ``plant``:
        body_poses: ``list[RigidTransform]`` (the plant's body poses port).
        body_spatial_velocities: ``list[SpatialVelocity]`` (the plant's port).
    Input port, with ``plant``:
        plant_state: (n_q + n_v) the plant's state port [q; v]; the element
            computes the two bodies' poses and velocities from it in a
            private context of ``plant`` (the same numbers as the list ports;
            the plant's default parameters, see ``__init__``).
    Output ports:
        spatial_forces: ``list[ExternallyAppliedSpatialForce]`` -- +F on the
            indenter at the tip, -F on the phantom body; connect to the
            plant's applied spatial force input.
        tissue.force_W: (3,) true tissue force on the tip in W, N (z >= 0
            up, the Hunt-Crossley law; x, y the optional normal tilt and
            friction, else 0).
        tissue.penetration: (1,) eps, m.
        tissue.surface_z: (1,) tissue surface height under the tip in W, m.
        probe.position: (3,) p_WT, m, and probe.velocity: (3,) v_WT, m/s
            (the probe tip's kinematics, computed here anyway; the station
            exports them under the same names).
        tissue.sample: (17,) the same quantities (:data:`SAMPLE_FIELDS`) as
            this element's state after its last tick, for loggers: read
            after a tick it equals the ports above at no cost.

    The ports above are computed from the inputs (and the relaxation state),
    so they are right in any context. ``tissue.sample`` and, in a
    simulation, ``spatial_forces`` come from the state that the tick's
    update stores (see below).

    Discrete state, updated every ``update_period_s``: the K relaxation
    branch states (with a relaxation only), m^beta
    (:func:`vic_drake.tissue.relaxation_step`, exact for the penetration
    held over the tick); the sample; and the tick it is valid for.

    Timing: the plant's discrete step is an unrestricted update, which the
    Simulator runs before the discrete updates of the same tick; so this
    element's update sees the plant state of the next tick, and the sample
    it stores (with the branch states after the tick) is exactly the
    contact the next plant step asks for. ``spatial_forces`` uses it when
    the context's time is that tick; otherwise (a context set by hand, no
    tick yet) it computes the contact from the inputs. An initialization
    event stores the first sample. Set a state by hand only before
    ``Simulator.Initialize`` (or take one step after it), as for the
    plant's sampled output ports.

    Outputs depend on the plant's state and this state only (no direct
    feedthrough from the applied-force input), so the loop through the plant
    is not algebraic.
    """

    def __init__(
        self,
        phantom: Phantom,
        *,
        indenter_body_index: BodyIndex,
        p_BT,
        phantom_body_index: BodyIndex,
        lookup_resolution_m: float = 0.0005,
        friction_coefficient: float = 0.0,
        slip_speed_m_per_s: float = 0.005,
        along_normal: bool = False,
        relaxation: RelaxationParams | None = None,
        update_period_s: float = DEFAULT_UPDATE_PERIOD_S,
        plant: MultibodyPlant | None = None,
    ):
        """
        Args:
            phantom: the tissue map (in the phantom body's frame).
            indenter_body_index: body B carrying the tip.
            p_BT: tip position in B's frame, m (3,).
            phantom_body_index: the phantom body (receives the reaction).
            lookup_resolution_m: grid of the per-step lookup for phantoms
                that are not grids (see :class:`~vic_drake.tissue.PointLookup`), m.
            friction_coefficient, slip_speed_m_per_s: optional tangential
                friction (see :func:`tip_contact`); 0 = the paper's model.
            along_normal: force along the surface normal instead of
                vertical (see :func:`tip_contact`).
            relaxation: the tissue's stress relaxation
                (:mod:`vic_drake.tissue.relaxation`; the phantom's kappa is
                then the instantaneous modulus); None: plain Hunt-Crossley.
            update_period_s: period of the state's update (the plant's
                step), s.
            plant: the finalized MultibodyPlant the body indices belong to:
                the element then reads the plant's state (input
                "plant_state") instead of the body pose and velocity lists.
                Its private context has the plant's default parameters: a
                diagram context whose plant parameters move frames (joint
                offsets) must use the list ports (no plant).
        """
        if not (np.isfinite(update_period_s) and update_period_s > 0):
            raise VicDrakeError(f"update_period_s must be > 0, got {update_period_s!r}")
        if not (np.isfinite(friction_coefficient) and friction_coefficient >= 0):
            raise VicDrakeError(
                f"friction_coefficient must be >= 0, got {friction_coefficient!r}"
            )
        if not (np.isfinite(slip_speed_m_per_s) and slip_speed_m_per_s > 0):
            raise VicDrakeError(
                f"slip_speed_m_per_s must be > 0, got {slip_speed_m_per_s!r}"
            )
        super().__init__()
        self._settings = (
            float(friction_coefficient),
            float(slip_speed_m_per_s),
            bool(along_normal),
        )
        self._phantom = phantom.point_lookup(resolution_m=lookup_resolution_m)
        self._beta = float(self._phantom.beta)
        self._period = float(update_period_s)
        self._indenter = indenter_body_index
        self._phantom_body = phantom_body_index
        on_tip = ExternallyAppliedSpatialForce()
        on_tip.body_index = indenter_body_index
        on_tip.p_BoBq_B = np.asarray(p_BT, float).reshape(3)
        on_phantom = ExternallyAppliedSpatialForce()
        on_phantom.body_index = phantom_body_index
        self._applied = [on_tip, on_phantom]
        self._zero_torque = np.zeros(3)
        self._i_indenter, self._i_phantom = (
            int(indenter_body_index),
            int(phantom_body_index),
        )
        self._p_BT = np.asarray(p_BT, float).reshape(3).tolist()
        self._poses_port = self._velocities_port = self._state_port = None
        if plant is None:
            self._poses_port = self.DeclareAbstractInputPort(
                "body_poses", AbstractValue.Make([RigidTransform()])
            )
            self._velocities_port = self.DeclareAbstractInputPort(
                "body_spatial_velocities", AbstractValue.Make([SpatialVelocity()])
            )
            self._kinematics = self._kinematics_from_lists
        else:
            self._reader = PlantBodyReader(
                plant, (indenter_body_index, phantom_body_index)
            )
            self._state_port = self.DeclareVectorInputPort(
                "plant_state", self._reader.num_states
            )
            self._kinematics = self._kinematics_from_plant
        # Relaxation: the branch states (m^beta), updated exactly for the
        # penetration held over each tick.
        self._branches = None
        self._g = self._decay = ()
        prerequisites = {self.all_input_ports_ticket()}
        if relaxation is not None and relaxation.n_branches:
            self._g = tuple(float(g) for g in relaxation.fractions)
            # exp(-dt / tau_i), as relaxation_step computes it.
            self._decay = tuple(
                np.exp(-self._period / np.asarray(relaxation.time_constants_s, float))
                .astype(float)
                .tolist()
            )
            self._branches = self.DeclareDiscreteState(relaxation.n_branches)
            prerequisites.add(self.discrete_state_ticket(self._branches))
        self._sample = self.DeclareDiscreteState(_SAMPLE_SIZE)
        self._sample_tick = self.DeclareDiscreteState([-1.0])  # none yet
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, 0.0, self._update)
        self.DeclareInitializationDiscreteUpdateEvent(self._initialize)
        self._contact_cache = self.DeclareCacheEntry(
            description="tip_contact",
            value_producer=ValueProducer(
                allocate=AbstractValue.Make(()).Clone, calc=self._calc_contact
            ),
            prerequisites_of_calc=prerequisites,
        )
        live = {self._contact_cache.ticket()}
        self._forces_port = self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]),
            self._calc_spatial_forces,
            prerequisites_of_calc={
                self.all_input_ports_ticket(),
                self.all_state_ticket(),
                self.time_ticket(),
            },
        )
        self._force_port = self.DeclareVectorOutputPort(
            "tissue.force_W",
            3,
            lambda c, out: out.SetFromVector(np.array(self._contact_cache.Eval(c)[2])),
            prerequisites_of_calc=live,
        )
        self._penetration_port = self.DeclareVectorOutputPort(
            "tissue.penetration",
            1,
            lambda c, out: out.SetAtIndex(0, self._contact_cache.Eval(c)[3][1]),
            prerequisites_of_calc=live,
        )
        self._surface_port = self.DeclareVectorOutputPort(
            "tissue.surface_z",
            1,
            lambda c, out: out.SetAtIndex(0, self._contact_cache.Eval(c)[3][3]),
            prerequisites_of_calc=live,
        )
        self._tip_position_port = self.DeclareVectorOutputPort(
            "probe.position",
            3,
            lambda c, out: out.SetFromVector(self._contact_cache.Eval(c)[0]),
            prerequisites_of_calc=live,
        )
        self._tip_velocity_port = self.DeclareVectorOutputPort(
            "probe.velocity",
            3,
            lambda c, out: out.SetFromVector(self._contact_cache.Eval(c)[1]),
            prerequisites_of_calc=live,
        )
        self._sample_port = self.DeclareStateOutputPort("tissue.sample", self._sample)

    def get_body_poses_input_port(self):
        return port_or_error(self._poses_port, "body_poses", "a plant")

    def get_body_spatial_velocities_input_port(self):
        return port_or_error(
            self._velocities_port, "body_spatial_velocities", "a plant"
        )

    def get_plant_state_input_port(self):
        return port_or_error(self._state_port, "plant_state", "no plant")

    def get_spatial_forces_output_port(self):
        return self._forces_port

    def get_force_output_port(self):
        return self._force_port

    def get_penetration_output_port(self):
        return self._penetration_port

    def get_surface_z_output_port(self):
        return self._surface_port

    def get_tip_position_output_port(self):
        return self._tip_position_port

    def get_tip_velocity_output_port(self):
        return self._tip_velocity_port

    def get_sample_output_port(self):
        return self._sample_port

    def tip_position(self, context) -> np.ndarray:
        """p_WT, m, from the inputs."""
        return self._contact_cache.Eval(context)[0].copy()

    def contact(self, context) -> TipContact:
        """The tissue at the tip in this context (from the inputs and state)."""
        return TipContact(*self._contact_cache.Eval(context)[3])

    def get_relaxation_state_index(self):
        """Index of the relaxation branch states (None without relaxation)."""
        return self._branches

    def _relaxed(self, context) -> float:
        """sum_i g_i s_i of the branch states in ``context``, m^beta."""
        if self._branches is None:
            return 0.0
        return self._weighted(
            context.get_discrete_state(self._branches).value().tolist()
        )

    def _weighted(self, s) -> float:
        """sum_i g_i s_i of branch states ``s``, m^beta."""
        return sum(g * s_i for g, s_i in zip(self._g, s, strict=True))

    def _kinematics_from_lists(self, context):
        """X_WB (3 x 4 rows), V_WB ([w; v]), p_WPh, v_WPh as lists of floats."""
        poses = self._poses_port.Eval(context)
        velocities = self._velocities_port.Eval(context)
        return (
            poses[self._i_indenter].GetAsMatrix34().tolist(),
            velocities[self._i_indenter].get_coeffs().tolist(),
            poses[self._i_phantom].translation().tolist(),
            velocities[self._i_phantom].get_coeffs()[3:].tolist(),
        )

    def _kinematics_from_plant(self, context):
        """As :meth:`_kinematics_from_lists`, from the plant's state input."""
        (X, V), (X_Ph, V_Ph) = self._reader(self._state_port.Eval(context))
        return (
            X.GetAsMatrix34().tolist(),
            V.get_coeffs().tolist(),
            X_Ph.translation().tolist(),
            V_Ph.get_coeffs()[3:].tolist(),
        )

    def _calc_contact(self, context, value):
        # Cached: p_WT, v_WT (arrays), f_W, the contact terms, the map sample,
        # then p_WT, v_WT, p_WPh, v_WPh as lists of floats.
        X, V, p_WPh, v_WPh = self._kinematics(context)
        bx, by, bz = self._p_BT
        # p_BT expressed in W (R p_BT), in Eigen's order of the product.
        r = [row[0] * bx + row[1] * by + row[2] * bz for row in X]
        p_WT = [X[0][3] + r[0], X[1][3] + r[1], X[2][3] + r[2]]
        w = V[:3]
        v_WT = [
            V[3] + (w[1] * r[2] - w[2] * r[1]),
            V[4] + (w[2] * r[0] - w[0] * r[2]),
            V[5] + (w[0] * r[1] - w[1] * r[0]),
        ]
        sample = self._phantom(p_WT[0] - p_WPh[0], p_WT[1] - p_WPh[1])
        terms = contact_terms(
            sample, self._beta, p_WT, v_WT, p_WPh, v_WPh, *self._settings,
            self._relaxed(context),
        )  # fmt: skip
        # Vectors for the output ports as arrays: pybind copies an array into
        # a port several times faster than a list.
        value.set_value(
            (np.array(p_WT), np.array(v_WT), force_W_of_terms(terms), terms, sample,
             p_WT, v_WT, p_WPh, v_WPh)
        )  # fmt: skip

    def _store(self, discrete_state, cached, terms, tick: float) -> None:
        """Stores the sample of the cached kinematics with ``terms``, for ``tick``."""
        _, _, _, _, _, p_WT, v_WT, p_WPh, _ = cached
        force, eps, eps_dot, surface, kappa, lam = terms[:6]
        discrete_state.set_value(
            self._sample,
            np.array([
                *p_WT, *v_WT, *force_W_of_terms(terms), eps, eps_dot, surface, kappa, lam,
                p_WT[0] - p_WPh[0], p_WT[1] - p_WPh[1], p_WT[2] - p_WPh[2],
            ]),
        )  # fmt: skip
        discrete_state.get_mutable_value(self._sample_tick)[0] = tick

    def _tick(self, context) -> float:
        return float(round(context.get_time() / self._period))

    def _initialize(self, context, discrete_state):
        # The cached terms are those of this context's branch states.
        cached = self._contact_cache.Eval(context)
        self._store(discrete_state, cached, cached[3], self._tick(context))

    def _update(self, context, discrete_state):
        cached = self._contact_cache.Eval(context)
        terms = cached[3]
        if self._branches is not None:
            eps = terms[1]
            u = (eps if eps > 0.0 else 0.0) ** self._beta  # relaxation_input
            # discrete_state holds the current state on entry (a LeafSystem
            # copies it in before calling an update handler).
            s = discrete_state.value(self._branches).tolist()
            # relaxation_step: u + (s - u) exp(-dt / tau), per branch.
            s = [u + (s_i - u) * d for s_i, d in zip(s, self._decay, strict=True)]
            discrete_state.set_value(self._branches, np.array(s))
            # The same kinematics and map sample, with the branches after the tick.
            sample, p_WT, v_WT, p_WPh, v_WPh = cached[4:]
            terms = contact_terms(
                sample, self._beta, p_WT, v_WT, p_WPh, v_WPh, *self._settings,
                self._weighted(s),
            )  # fmt: skip
        self._store(discrete_state, cached, terms, self._tick(context) + 1.0)

    def _calc_spatial_forces(self, context, output):
        state = context.get_discrete_state()  # one crossing for both groups
        if state.value(self._sample_tick)[0] == self._tick(context):
            sample = state.value(self._sample)
            f_W, p_PhT = sample[6:9], sample[14:17]
        else:  # No tick stored for this time: from the inputs.
            _, _, f_W, _, _, p_WT, _, p_WPh, _ = self._contact_cache.Eval(context)
            f_W = np.array(f_W)
            p_PhT = np.array([p_WT[i] - p_WPh[i] for i in range(3)])
        # set_value copies the list into the port's value, so the two force
        # records are kept and refilled (this runs every plant step).
        on_tip, on_phantom = self._applied
        on_tip.F_Bq_W = SpatialForce(self._zero_torque, f_W)
        # The reaction acts on the phantom (which only translates) at the
        # same world point.
        on_phantom.p_BoBq_B = p_PhT
        on_phantom.F_Bq_W = SpatialForce(self._zero_torque, -f_W)
        output.set_value(self._applied)


__all__ = ["SAMPLE_FIELDS", "TipContact", "TissueForceElement", "tip_contact"]
