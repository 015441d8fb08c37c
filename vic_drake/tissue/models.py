"""Tissue force laws: Hunt-Crossley and Kelvin-Voigt (vectorised numpy).

Sign convention: penetration ``eps`` is positive into the body (surface
height minus tip height), ``eps_dot`` its time derivative, and the returned
force is the magnitude of the tissue's push-back along the outward normal
(positive = body pushes the probe up). Both laws return 0 out of contact
(eps < 0). Neither law clips a negative (adhesive) result in contact: the
fits need the raw law, and the force element clips where physics requires
(see ``hunt_crossley_force(..., clip_tension=True)``).
"""

from __future__ import annotations

import numpy as np


def hunt_crossley_force(
    eps,
    eps_dot,
    kappa,
    lam,
    beta: float,
    *,
    clip_tension: bool = False,
):
    """Hunt-Crossley force kappa eps^beta + lam eps^beta eps_dot (eq. 1).

    Args:
        eps: penetration, m (array-like; eps < 0 is out of contact).
        eps_dot: penetration rate, m/s.
        kappa: elasticity, N/m^beta.
        lam: viscosity, N s/m^(beta+1).
        beta: exponent (> 0).
        clip_tension: if True, the force is never negative (tissue cannot
            pull the probe), as in a physical contact element.

    Returns:
        Force in N, broadcast shape of the inputs.
    """
    eps = np.asarray(eps, dtype=float)
    eps_pos = np.where(eps > 0.0, eps, 0.0)
    eps_beta = eps_pos**beta
    force = eps_beta * (np.asarray(kappa, float) + np.asarray(lam, float) * eps_dot)
    force = np.where(eps > 0.0, force, 0.0)
    if clip_tension:
        force = np.maximum(force, 0.0)
    return force


def kelvin_voigt_force(eps, eps_dot, k, d, *, clip_tension: bool = False):
    """Kelvin-Voigt force k eps + d eps_dot for eps >= 0, else 0.

    Args:
        eps: penetration, m. eps_dot: penetration rate, m/s.
        k: stiffness, N/m. d: damping, N s/m.
    """
    eps = np.asarray(eps, dtype=float)
    force = np.where(eps > 0.0, k * eps + d * np.asarray(eps_dot, float), 0.0)
    if clip_tension:
        force = np.maximum(force, 0.0)
    return force


def hunt_crossley_penetration(force, kappa, beta: float):
    """Static penetration at which HC's elastic part gives ``force`` (eps_dot = 0)."""
    force = np.maximum(np.asarray(force, float), 0.0)
    return (force / np.asarray(kappa, float)) ** (1.0 / beta)
