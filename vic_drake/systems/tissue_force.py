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
  beta, clip_tension=True)`` (zero out of contact, never pulling), applied
  along +z of W at T on the indenter body; the equal and opposite force acts
  on the phantom body at the same point. The map's kappa and lambda were
  fitted to vertical indentations, so the force is vertical; tangential
  (friction) forces are not modelled.
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

from vic_drake.tissue import Phantom, hunt_crossley_force


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
    """

    force_N: float
    penetration_m: float
    penetration_rate_m_per_s: float
    surface_z_m: float
    kappa: float
    lam: float


def tip_contact(
    phantom: Phantom,
    p_WT,
    v_WT,
    p_WPh=(0.0, 0.0, 0.0),
    v_WPh=(0.0, 0.0, 0.0),
) -> TipContact:
    """Hunt-Crossley contact of the probe tip T with a translated phantom Ph.

    Args:
        phantom: the tissue map, in the phantom body's frame.
        p_WT: tip position in W, m (3,).
        v_WT: tip translational velocity in W, m/s (3,).
        p_WPh: phantom body origin in W (its map offset plus lift), m (3,).
        v_WPh: phantom body translational velocity in W, m/s (3,).

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
    force = float(
        hunt_crossley_force(eps, eps_dot, s.kappa, s.lam, phantom.beta, clip_tension=True)
    )
    return TipContact(force, float(eps), float(eps_dot), surface, float(s.kappa), float(s.lam))


def _cross(a, b) -> np.ndarray:
    """a x b for 3-vectors (np.cross costs ~50 us per call; this runs each step)."""
    return np.array([
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ])


class TissueForceElement(LeafSystem):
    """Applies the Hunt-Crossley tissue force at the probe tip (see module doc).

    Input ports:
        body_poses: ``list[RigidTransform]`` (the plant's body poses port).
        body_spatial_velocities: ``list[SpatialVelocity]`` (the plant's port).
    Output ports:
        spatial_forces: ``list[ExternallyAppliedSpatialForce]`` -- +F on the
            indenter at the tip, -F on the phantom body; connect to the
            plant's applied spatial force input.
        force_W: (3,) true tissue force on the tip in W, N (z >= 0 up).
        penetration: (1,) eps, m.
        surface_z: (1,) tissue surface height under the tip in W, m.

    Outputs depend on the plant's state only (no direct feedthrough from
    the applied-force input), so the loop through the plant is not algebraic.
    """

    def __init__(
        self,
        phantom: Phantom,
        *,
        indenter_body_index: BodyIndex,
        p_BT,
        phantom_body_index: BodyIndex,
    ):
        """
        Args:
            phantom: the tissue map (in the phantom body's frame).
            indenter_body_index: body B carrying the tip.
            p_BT: tip position in B's frame, m (3,).
            phantom_body_index: the phantom body (receives the reaction).
        """
        super().__init__()
        self._phantom = phantom
        self._indenter = indenter_body_index
        self._phantom_body = phantom_body_index
        self._p_BT = np.asarray(p_BT, float).reshape(3)
        self._poses_port = self.DeclareAbstractInputPort(
            "body_poses", AbstractValue.Make([RigidTransform()])
        )
        self._velocities_port = self.DeclareAbstractInputPort(
            "body_spatial_velocities", AbstractValue.Make([SpatialVelocity()])
        )
        model_value = AbstractValue.Make(TipContact(0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
        self._contact_cache = self.DeclareCacheEntry(
            description="tip_contact",
            value_producer=ValueProducer(allocate=model_value.Clone, calc=self._calc_contact),
            prerequisites_of_calc={self.all_input_ports_ticket()},
        )
        self._forces_port = self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]),
            self._calc_spatial_forces,
            prerequisites_of_calc={self._contact_cache.ticket()},
        )
        self._force_port = self.DeclareVectorOutputPort(
            "force_W", 3, self._calc_force,
            prerequisites_of_calc={self._contact_cache.ticket()},
        )
        self._penetration_port = self.DeclareVectorOutputPort(
            "penetration", 1,
            lambda c, out: out.SetAtIndex(0, self._contact(c).penetration_m),
            prerequisites_of_calc={self._contact_cache.ticket()},
        )
        self._surface_port = self.DeclareVectorOutputPort(
            "surface_z", 1,
            lambda c, out: out.SetAtIndex(0, self._contact(c).surface_z_m),
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

    def tip_position(self, context) -> np.ndarray:
        """p_WT, m, from the body poses input."""
        X_WB = self._poses_port.Eval(context)[int(self._indenter)]
        return X_WB @ self._p_BT

    def _contact(self, context) -> TipContact:
        return self._contact_cache.Eval(context)

    def _calc_contact(self, context, value):
        poses = self._poses_port.Eval(context)
        velocities = self._velocities_port.Eval(context)
        X_WB = poses[int(self._indenter)]
        V_WB = velocities[int(self._indenter)]
        p_BT_W = X_WB.rotation() @ self._p_BT
        v_WT = V_WB.translational() + _cross(V_WB.rotational(), p_BT_W)
        X_WPh = poses[int(self._phantom_body)]
        V_WPh = velocities[int(self._phantom_body)]
        value.set_value(
            tip_contact(
                self._phantom,
                X_WB.translation() + p_BT_W,
                v_WT,
                X_WPh.translation(),
                V_WPh.translational(),
            )
        )

    def _calc_force(self, context, output):
        output.SetFromVector([0.0, 0.0, self._contact(context).force_N])

    def _calc_spatial_forces(self, context, output):
        contact = self._contact(context)
        poses = self._poses_port.Eval(context)
        f_W = np.array([0.0, 0.0, contact.force_N])
        on_tip = ExternallyAppliedSpatialForce()
        on_tip.body_index = self._indenter
        on_tip.p_BoBq_B = self._p_BT
        on_tip.F_Bq_W = SpatialForce(np.zeros(3), f_W)
        # The reaction acts on the phantom at the same world point.
        X_WPh = poses[int(self._phantom_body)]
        p_WT = poses[int(self._indenter)] @ self._p_BT
        on_phantom = ExternallyAppliedSpatialForce()
        on_phantom.body_index = self._phantom_body
        on_phantom.p_BoBq_B = X_WPh.inverse() @ p_WT
        on_phantom.F_Bq_W = SpatialForce(np.zeros(3), -f_W)
        output.set_value([on_tip, on_phantom])
