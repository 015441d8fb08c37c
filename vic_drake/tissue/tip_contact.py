"""The Hunt-Crossley contact of the probe tip with a phantom, as a pure function.

:func:`tip_contact` is the tissue force element's law
(:class:`vic_drake.systems.tissue_force.TissueForceElement`; the geometry,
signs and the optional normal tilt, friction and relaxation are described
there); :func:`contact_terms` is the same on floats, the per-step path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vic_drake.tissue.phantom import Phantom, PointLookup


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


def contact_terms(
    sample, beta, p_WT, v_WT, p_WPh, v_WPh, mu, slip, along_normal, relaxed
) -> tuple:
    """The :class:`TipContact` fields, in order, computed on floats.

    ``sample`` is the map's ``(surface_z_m, dz_dx, dz_dy, kappa, lam)`` at
    the tip, in the phantom's frame; the vectors are 3-sequences of floats;
    ``mu``, ``slip``, ``along_normal`` and ``relaxed`` are
    :func:`tip_contact`'s friction, normal and relaxation settings. Plain
    Python floats: this runs every step, and numpy's per-call cost dominates
    at this size.
    """
    z_s, gx, gy, kappa, lam = sample
    surface = z_s + p_WPh[2]
    eps = surface - p_WT[2]
    vx, vy, vz = v_WT[0] - v_WPh[0], v_WT[1] - v_WPh[1], v_WT[2] - v_WPh[2]
    eps_dot = gx * vx + gy * vy - vz
    force = 0.0  # out of contact (the law's value too)
    if eps > 0.0:
        # hunt_crossley_force(eps, eps_dot, kappa, lam, beta), less the relaxed part.
        force = max(eps**beta * (kappa + lam * eps_dot) - kappa * relaxed, 0.0)
    fx = fy = tx = ty = 0.0
    if force > 0.0:
        if mu > 0.0:
            scale = -mu * force / math.sqrt(vx * vx + vy * vy + slip**2)
            fx, fy = scale * vx, scale * vy
        if along_normal:
            tx, ty = -gx * force, -gy * force
    return force, eps, eps_dot, surface, kappa, lam, fx, fy, tx, ty


_SAMPLE_FIELDS = ("surface_z_m", "dz_dx", "dz_dy", "kappa", "lam")


def _floats3(v) -> list[float]:
    return np.asarray(v, float).reshape(3).tolist()


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
    p_WT, v_WT = _floats3(p_WT), _floats3(v_WT)
    p_WPh, v_WPh = _floats3(p_WPh), _floats3(v_WPh)
    x_map, y_map = p_WT[0] - p_WPh[0], p_WT[1] - p_WPh[1]
    if isinstance(phantom, PointLookup):
        sample = phantom(x_map, y_map)
    else:
        s = phantom.sample(x_map, y_map)
        sample = tuple(float(getattr(s, name)) for name in _SAMPLE_FIELDS)
    return TipContact(
        *contact_terms(
            sample,
            float(phantom.beta),
            p_WT,
            v_WT,
            p_WPh,
            v_WPh,
            float(friction_coefficient),
            float(slip_speed_m_per_s),
            bool(along_normal),
            float(relaxed_m_beta),
        )
    )


def force_W_of_terms(terms) -> list[float]:
    """The whole force on the tip in W (:attr:`TipContact.force_W`) from the terms."""
    force, _, _, _, _, _, fx, fy, tx, ty = terms
    return [tx + fx, ty + fy, force]


__all__ = ["TipContact", "contact_terms", "force_W_of_terms", "tip_contact"]
