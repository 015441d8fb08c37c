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

from dataclasses import dataclass

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialForce, SpatialVelocity
from pydrake.multibody.plant import ExternallyAppliedSpatialForce
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.framework import LeafSystem, ValueProducer

from vic_drake.errors import VicDrakeError
from vic_drake.tissue import (
    DEFAULT_UPDATE_PERIOD_S,
    Phantom,
    PointLookup,
    RelaxationParams,
    hunt_crossley_force,
    relaxation_input,
    relaxation_step,
)


@dataclass(frozen=True)
class TipContact:
    """The tissue at the probe tip (scalars, SI units).

    Attributes:
        force_N: tissue force on the tip along +z of W (>= 0, up).
        penetration_m: eps, surface height minus tip height (< 0 out of contact).
        penetration_rate_m_per_s: eps_dot.
        surface_z_m: tissue surface height under the tip, in W.
        kappa: Hunt-Crossley elasticity at the tip, N/m^beta.
        lam: Hunt-Crossley viscosity at the tip, N s/m^(beta+1).
        friction_x_N, friction_y_N: optional tangential friction on the tip
            in W's x and y (zero unless a friction coefficient is set).
        tilt_x_N, tilt_y_N: the horizontal part of a force along the surface
            normal, ``-dz/dx F`` and ``-dz/dy F`` (zero for a vertical force).
    """

    force_N: float
    penetration_m: float
    penetration_rate_m_per_s: float
    surface_z_m: float
    kappa: float
    lam: float
    friction_x_N: float = 0.0
    friction_y_N: float = 0.0
    tilt_x_N: float = 0.0
    tilt_y_N: float = 0.0

    @property
    def force_W(self) -> np.ndarray:
        """The whole force on the tip in W, N: tilt + friction in x, y; HC in z."""
        return np.array(
            [
                self.tilt_x_N + self.friction_x_N,
                self.tilt_y_N + self.friction_y_N,
                self.force_N,
            ]
        )


@dataclass(frozen=True)
class _Cached:
    """Per-step cache of the force element: the contact and where it acts."""

    contact: TipContact
    p_WT: np.ndarray
    p_WPh: np.ndarray
    v_WT: np.ndarray
    f_W: np.ndarray  # contact.force_W


def tip_contact(
    phantom: Phantom | PointLookup,
    p_WT,
    v_WT,
    p_WPh=(0.0, 0.0, 0.0),
    v_WPh=(0.0, 0.0, 0.0),
    *,
    friction_coefficient: float = 0.0,
    slip_speed_m_per_s: float = 0.005,
    along_normal: bool = False,
    relaxed_m_beta: float = 0.0,
) -> TipContact:
    """Hunt-Crossley contact of the probe tip T with a translated phantom Ph.

    Args:
        phantom: the tissue map, in the phantom body's frame (a Phantom or
            its :class:`~vic_drake.tissue.PointLookup`).
        p_WT: tip position in W, m (3,).
        v_WT: tip translational velocity in W, m/s (3,).
        p_WPh: phantom body origin in W (its map offset plus lift), m (3,).
        v_WPh: phantom body translational velocity in W, m/s (3,).
        friction_coefficient: mu of an optional sliding friction in the
            horizontal plane, ``-mu F v_t / sqrt(|v_t|^2 + v_s^2)`` with v_t
            the tip's horizontal velocity relative to the phantom and F the
            Hunt-Crossley force (0: none, the paper's model).
        slip_speed_m_per_s: v_s, the regularisation speed of that friction.
        along_normal: if True the force acts along the surface's (unnormalised)
            normal ``F (-dz/dx, -dz/dy, 1)``, keeping the vertical component
            the fitted law; else it is vertical (the paper's 1-D model).
        relaxed_m_beta: ``sum_i g_i s_i`` of a relaxing tissue, m^beta
            (:func:`vic_drake.tissue.relaxing_hunt_crossley_force`; the
            phantom's kappa is then the instantaneous one); 0: plain HC.

    Returns:
        The :class:`TipContact` (see the module docstring for the formulas).
    """
    p_WT = np.asarray(p_WT, float)
    v_WT = np.asarray(v_WT, float)
    p_WPh = np.asarray(p_WPh, float)
    v_WPh = np.asarray(v_WPh, float)
    x_map, y_map = p_WT[0] - p_WPh[0], p_WT[1] - p_WPh[1]
    s = phantom.sample(x_map, y_map)
    surface = float(s.surface_z_m) + p_WPh[2]
    eps = surface - p_WT[2]
    v_rel = v_WT - v_WPh
    eps_dot = float(s.dz_dx) * v_rel[0] + float(s.dz_dy) * v_rel[1] - v_rel[2]
    force = 0.0  # out of contact (the law's value too; skips its numpy cost)
    if eps > 0.0:
        force = float(hunt_crossley_force(eps, eps_dot, s.kappa, s.lam, phantom.beta))
        force = max(force - float(s.kappa) * relaxed_m_beta, 0.0)
    fx = fy = 0.0
    if friction_coefficient > 0.0 and force > 0.0:
        vx, vy = float(v_rel[0]), float(v_rel[1])
        scale = (
            -friction_coefficient
            * force
            / np.sqrt(vx * vx + vy * vy + slip_speed_m_per_s**2)
        )
        fx, fy = scale * vx, scale * vy
    tx = ty = 0.0
    if along_normal and force > 0.0:
        tx, ty = -float(s.dz_dx) * force, -float(s.dz_dy) * force
    return TipContact(
        force,
        float(eps),
        float(eps_dot),
        surface,
        float(s.kappa),
        float(s.lam),
        fx,
        fy,
        tx,
        ty,
    )


def _cross(a, b) -> np.ndarray:
    """a x b for 3-vectors (cheaper than np.cross at this size; this runs each step)."""
    return np.array(
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    )


class TissueForceElement(LeafSystem):
    """Applies the Hunt-Crossley tissue force at the probe tip (see module doc).

    Input ports:
        body_poses: ``list[RigidTransform]`` (the plant's body poses port).
        body_spatial_velocities: ``list[SpatialVelocity]`` (the plant's port).
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

    Discrete state (with a relaxation only): the K relaxation branch states,
    m^beta, updated every ``update_period_s``
    (:func:`vic_drake.tissue.relaxation_step`, exact for the penetration
    held over the tick).

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
            update_period_s: period of the relaxation state's update, s.
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
        self._mu = float(friction_coefficient)
        self._along_normal = bool(along_normal)
        self._slip = float(slip_speed_m_per_s)
        super().__init__()
        self._phantom = phantom.point_lookup(resolution_m=lookup_resolution_m)
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
        self._p_BT = np.asarray(p_BT, float).reshape(3)
        self._poses_port = self.DeclareAbstractInputPort(
            "body_poses", AbstractValue.Make([RigidTransform()])
        )
        self._velocities_port = self.DeclareAbstractInputPort(
            "body_spatial_velocities", AbstractValue.Make([SpatialVelocity()])
        )
        # Relaxation: one discrete state vector (the branch states, m^beta),
        # updated exactly for the penetration held over each tick.
        self._branches = None
        prerequisites = {self.all_input_ports_ticket()}
        if relaxation is not None and relaxation.n_branches:
            self._g = np.asarray(relaxation.fractions)
            self._taus = np.asarray(relaxation.time_constants_s)
            self._period = float(update_period_s)
            self._branches = self.DeclareDiscreteState(relaxation.n_branches)
            self.DeclarePeriodicDiscreteUpdateEvent(
                float(update_period_s), 0.0, self._update_relaxation
            )
            prerequisites.add(self.discrete_state_ticket(self._branches))
        model_value = AbstractValue.Make(
            _Cached(
                TipContact(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
                np.zeros(3),
                np.zeros(3),
                np.zeros(3),
                np.zeros(3),
            )
        )
        self._contact_cache = self.DeclareCacheEntry(
            description="tip_contact",
            value_producer=ValueProducer(
                allocate=model_value.Clone, calc=self._calc_contact
            ),
            prerequisites_of_calc=prerequisites,
        )
        self._forces_port = self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]),
            self._calc_spatial_forces,
            prerequisites_of_calc={self._contact_cache.ticket()},
        )
        self._force_port = self.DeclareVectorOutputPort(
            "tissue.force_W",
            3,
            self._calc_force,
            prerequisites_of_calc={self._contact_cache.ticket()},
        )
        self._penetration_port = self.DeclareVectorOutputPort(
            "tissue.penetration",
            1,
            lambda c, out: out.SetAtIndex(0, self._contact(c).penetration_m),
            prerequisites_of_calc={self._contact_cache.ticket()},
        )
        self._surface_port = self.DeclareVectorOutputPort(
            "tissue.surface_z",
            1,
            lambda c, out: out.SetAtIndex(0, self._contact(c).surface_z_m),
            prerequisites_of_calc={self._contact_cache.ticket()},
        )

        self._tip_position_port = self.DeclareVectorOutputPort(
            "probe.position",
            3,
            lambda c, out: out.SetFromVector(self._contact_cache.Eval(c).p_WT),
            prerequisites_of_calc={self._contact_cache.ticket()},
        )
        self._tip_velocity_port = self.DeclareVectorOutputPort(
            "probe.velocity",
            3,
            lambda c, out: out.SetFromVector(self._contact_cache.Eval(c).v_WT),
            prerequisites_of_calc={self._contact_cache.ticket()},
        )

    def get_body_poses_input_port(self):
        return self._poses_port

    def get_body_spatial_velocities_input_port(self):
        return self._velocities_port

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

    def tip_position(self, context) -> np.ndarray:
        """p_WT, m, from the body poses input."""
        return self._contact_cache.Eval(context).p_WT.copy()

    def _contact(self, context) -> TipContact:
        return self._contact_cache.Eval(context).contact

    def get_relaxation_state_index(self):
        """Index of the relaxation branch states (None without relaxation)."""
        return self._branches

    def _update_relaxation(self, context, discrete_state):
        u = relaxation_input(self._contact(context).penetration_m, self._phantom.beta)
        s = context.get_discrete_state(self._branches).get_value()
        discrete_state.get_mutable_vector(self._branches).SetFromVector(
            relaxation_step(s, u, self._period, self._taus)
        )

    def _calc_contact(self, context, value):
        poses = self._poses_port.Eval(context)
        velocities = self._velocities_port.Eval(context)
        X_WB = poses[self._i_indenter]
        V_WB = velocities[self._i_indenter]
        p_BT_W = X_WB.rotation() @ self._p_BT
        p_WT = X_WB.translation() + p_BT_W
        v_WT = V_WB.translational() + _cross(V_WB.rotational(), p_BT_W)
        p_WPh = poses[self._i_phantom].translation()
        V_WPh = velocities[self._i_phantom]
        relaxed = 0.0
        if self._branches is not None:
            relaxed = float(
                self._g @ context.get_discrete_state(self._branches).get_value()
            )
        contact = tip_contact(
            self._phantom,
            p_WT,
            v_WT,
            p_WPh,
            V_WPh.translational(),
            friction_coefficient=self._mu,
            slip_speed_m_per_s=self._slip,
            along_normal=self._along_normal,
            relaxed_m_beta=relaxed,
        )
        value.set_value(_Cached(contact, p_WT, p_WPh, v_WT, contact.force_W))

    def _calc_force(self, context, output):
        output.SetFromVector(self._contact_cache.Eval(context).f_W)

    def _calc_spatial_forces(self, context, output):
        cached = self._contact_cache.Eval(context)
        f_W = cached.f_W
        # set_value copies the list into the port's value, so the two force
        # records are kept and refilled (this runs every plant step).
        on_tip, on_phantom = self._applied
        on_tip.F_Bq_W = SpatialForce(self._zero_torque, f_W)
        # The reaction acts on the phantom (which only translates) at the
        # same world point.
        on_phantom.p_BoBq_B = cached.p_WT - cached.p_WPh
        on_phantom.F_Bq_W = SpatialForce(self._zero_torque, -f_W)
        output.set_value(self._applied)
