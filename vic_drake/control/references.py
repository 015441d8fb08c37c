"""Force references of the four controllers, contact and penetration rate.

Sign conventions: forces are in the F/T sensor's convention (negative z =
the probe presses into the body), as the real logs' columns and the QP's
F_ext = K e + D e_dot with e = x_d - x (a target below the probe pulls it
down, a negative force). Penetration eps = surface_z - z is positive inside
the body; the Hunt-Crossley force (kappa + lam eps_dot) eps^beta pushes the
probe up, so a pressing reference is its negative.

Penetration rate (eq. 10 of the paper): eps_dot = z_surface_dot - z_dot,
with z_surface_dot the rate of the surface height under the moving probe
(the paper writes -z_dot - grad z . d with d the direction of motion taken
the other way round; this is the real controller's sign, checked on its
logs). Two estimates of z_surface_dot (:class:`ReferenceParams`):

- "moving_average": the real controller's filter, the mean of the last N
  finite differences (z_s(k) - z_s(k-1)) / dt of the map height under the
  probe (N = 10). State: see :func:`surface_velocity_initial_state`.
- "gradient": grad z(x, y) . (x_dot, y_dot), instantaneous, no state.

Controllers (details in :class:`vic_drake.control.params.ReferenceParams`):
CS and CF do not use the QP; VS-CF and VS-VF feed F_ref and F_min to it.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from vic_drake.control.params import ReferenceParams, StiffnessQpParams


class ForceReferences(NamedTuple):
    """One tick's references (length-3 tuples, N, sensor convention).

    Attributes:
        force_ref: F_ref for the QP (and, for CF, the z force target).
        force_min: F_min for the QP.
        target_force: the force the compliance (FDCC) stage must track;
            nonzero only for CF (z).
    """

    force_ref: tuple
    force_min: tuple
    target_force: tuple


def in_contact(force_z_N: float, params: ReferenceParams) -> bool:
    """Contact when the sensor's z force is below -threshold (pressing)."""
    return force_z_N < -params.contact_threshold_N


def penetration(surface_z_m: float, z_m: float) -> float:
    """eps = surface height - tip height, m (positive inside the body)."""
    return surface_z_m - z_m


def penetration_rate(z_dot: float, surface_velocity: float) -> float:
    """eps_dot = z_surface_dot - z_dot, m/s."""
    return surface_velocity - z_dot


def hunt_crossley_at_depth(
    kappa: float, lam: float, eps_m: float, eps_dot: float, beta: float
) -> float:
    """(kappa + lam eps_dot) eps^beta, N: the HC force at depth eps (0 if eps <= 0)."""
    if eps_m <= 0.0:
        return 0.0
    return (kappa + lam * eps_dot) * eps_m**beta


def surface_velocity_initial_state(window: int) -> list[float]:
    """State of the moving-average filter: [started, z_prev, next, d_0..d_{N-1}]."""
    return [0.0, 0.0, 0.0] + [0.0] * window


def surface_velocity_step(
    state, surface_z_m: float, dt: float
) -> tuple[list[float], float]:
    """One tick of the real controller's surface-velocity filter.

    The first tick only records the height (rate 0; the real controller
    started from an uninitialised previous height).

    Args:
        state: from :func:`surface_velocity_initial_state` (not modified).
        surface_z_m: map height under the probe this tick, m.
        dt: tick duration, s (> 0; a non-positive dt adds a zero rate).

    Returns:
        (new_state, mean rate over the window in m/s).
    """
    new = list(state)
    window = len(new) - 3
    if new[0] > 0.0 and dt > 0.0:
        rate = (surface_z_m - new[1]) / dt
    else:
        rate = 0.0
    slot = int(new[2])
    new[3 + slot] = rate
    new[2] = float((slot + 1) % window)
    new[0] = 1.0
    new[1] = surface_z_m
    return new, sum(new[3:]) / window


def surface_velocity_gradient(
    dz_dx: float, dz_dy: float, vx: float, vy: float
) -> float:
    """grad z . (vx, vy), m/s."""
    return dz_dx * vx + dz_dy * vy


def desired_penetration(ref: ReferenceParams, t_s: float) -> float:
    """VS-VF's desired penetration at time t, m: ``eps_d_m``, plus the dither
    ``penetration_dither_m sin(2 pi penetration_dither_hz t)`` when it is on.
    """
    a = ref.penetration_dither_m
    if a == 0.0:
        return ref.eps_d_m
    return ref.eps_d_m + a * math.sin(2.0 * math.pi * ref.penetration_dither_hz * t_s)


def force_references(
    *,
    contact: bool,
    kappa: float,
    lam: float,
    eps_dot: float,
    beta: float,
    ref: ReferenceParams,
    qp: StiffnessQpParams,
    t_s: float = 0.0,
) -> ForceReferences:
    """F_ref, F_min and the FDCC target force of the selected controller.

    Args:
        contact: from :func:`in_contact`.
        kappa, lam: Hunt-Crossley parameters under the probe.
        eps_dot: penetration rate, m/s (:func:`penetration_rate`).
        beta: HC exponent of the map.
        ref: controller kind and reference settings.
        qp: F_min (x, y and out of contact z) and F_max.
        t_s: the tick's time, s (read only by VS-VF's dither).

    Returns:
        ForceReferences. CS: all zero, F_min = qp.force_min_N. CF: F_ref
        and target force (0, 0, -force_ref_N). VS-CF: F_ref,z =
        -force_ref_N and F_min,z = -(kappa + lam eps_dot) eps_max^beta in
        contact. VS-VF: F_ref,z = -(kappa + lam eps_dot) eps_d(t)^beta
        (:func:`desired_penetration`; with its dither F_min,z is scaled by
        min(1, (eps_d(t) / eps_d_m)^beta) too) and
        F_min,z = force_min_z_N in contact. Out of contact the VS
        controllers use F_ref = 0, F_min,z = -F_max,z.
    """
    f_min = qp.force_min_N
    zero = (0.0, 0.0, 0.0)
    kind = ref.controller
    if kind == "cs":
        return ForceReferences(zero, (f_min[0], f_min[1], f_min[2]), zero)
    if kind == "cf":
        target = (0.0, 0.0, -ref.force_ref_N)
        return ForceReferences(target, (f_min[0], f_min[1], f_min[2]), target)
    if not contact:
        return ForceReferences(zero, (f_min[0], f_min[1], -qp.force_max_N[2]), zero)
    if kind == "vs-cf":
        f_ref_z = -ref.force_ref_N
        f_min_z = -(kappa + lam * eps_dot) * ref.eps_max_m**beta
    else:  # "vs-vf"
        eps_d = desired_penetration(ref, t_s)
        f_ref_z = -(kappa + lam * eps_dot) * eps_d**beta
        f_min_z = ref.force_min_z_N
        if eps_d < ref.eps_d_m:
            # The dither lowers the bound with the reference (where the force
            # sits at the bound, on ribs, the tip keeps moving), never
            # raises it.
            f_min_z *= (eps_d / ref.eps_d_m) ** beta
    return ForceReferences((0.0, 0.0, f_ref_z), (f_min[0], f_min[1], f_min_z), zero)


def constant_stiffness(ref: ReferenceParams) -> tuple[float, float, float] | None:
    """The fixed stiffness of CS (all axes) or CF (x, y; z = 0); None for VS."""
    k = ref.constant_stiffness_N_per_m
    if ref.controller == "cs":
        return (float(k[0]), float(k[1]), float(k[2]))
    if ref.controller == "cf":
        return (float(k[0]), float(k[1]), 0.0)
    return None


def uses_qp(ref: ReferenceParams) -> bool:
    """True for the variable-stiffness controllers (VS-CF, VS-VF)."""
    return ref.controller in ("vs-cf", "vs-vf")


def has_tank(ref: ReferenceParams) -> bool:
    """True for the controllers with an energy tank: VS-CF and VS-VF.

    CS and CF run no QP and have no tank; their logged tank only holds its
    initial energy (``tank_energy_J`` constant, ``tank_power_W`` 0), which
    is not a tank figure: their tank metrics are NaN.
    """
    return uses_qp(ref)


def scalar_sampler(phantom):
    """A fast scalar lookup ``f(x, y) -> (surface_z, dz_dx, dz_dy, kappa, lam)``.

    ``Phantom.sample`` is vectorised numpy, costly for one point at every
    tick (see docs/decisions.md, "Phantom lookup per tick"); this returns
    the phantom's cached :class:`~vic_drake.tissue.PointLookup` (exact for
    a GridPhantom, a 0.5 mm rasterization otherwise).
    """
    return phantom.point_lookup()
