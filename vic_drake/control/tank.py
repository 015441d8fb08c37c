"""The energy tank of the paper (Sec. II-B), one control tick at a time.

The tank has state x_t and energy T = x_t^2 / 2. With the position error
e = x_d - x, the velocity error e_dot = -x_dot (the real controller's
choice: the target's own velocity is ignored), the time-varying part of the
stiffness K^v = K - K_min and the damping D, the tank power is

    dT/dt = e' K^v e_dot + sigma e_dot' D e_dot,

where sigma = 1 stores the energy dissipated by the damping and sigma = 0
switches storage off once T >= T_max. Per tick (period dt, forward Euler
as the real controller):

    T+ = T + (e' (K - K_min) e_dot + sigma e_dot' D e_dot) dt.

The variable stiffness is enabled only while T >= T_min; otherwise
K = K_min (w = 0 in the paper) and, with ``floor_at_min``, the tank is reset
to T_min + sigma e_dot' D e_dot dt as the real controller did. The QP keeps
T+ >= T_min and dT/dt >= eta through :func:`tank_qp_rows`.

All functions take plain floats or length-3 sequences and return floats:
they run every 2 ms and numpy's per-call overhead dominates at this size.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from vic_drake.control.params import TankParams


class TankStep(NamedTuple):
    """The tank after one tick.

    Attributes:
        energy_J: T after the tick.
        power_W: dT/dt applied during the tick.
        sigma: 0 or 1, from T before the tick.
        enabled: True when T before the tick was >= T_min (variable
            stiffness allowed).
    """

    energy_J: float
    power_W: float
    sigma: float
    enabled: bool


def tank_energy(x_t: float) -> float:
    """T = x_t^2 / 2, J."""
    return 0.5 * x_t * x_t


def tank_state(energy_J: float) -> float:
    """x_t = sqrt(2 T) (T clipped at 0)."""
    return math.sqrt(2.0 * max(energy_J, 0.0))


def tank_sigma(energy_J: float, params: TankParams) -> float:
    """sigma = 0 when T >= T_max (tank full: stop storing), else 1."""
    return 0.0 if energy_J >= params.max_energy_J else 1.0


def tank_enabled(energy_J: float, params: TankParams) -> bool:
    """True when the variable stiffness may draw on the tank (T >= T_min)."""
    return energy_J >= params.min_energy_J


def damping_power(e_dot, damping, sigma: float) -> float:
    """sigma e_dot' D e_dot for a diagonal D, W."""
    return sigma * (
        damping[0] * e_dot[0] * e_dot[0]
        + damping[1] * e_dot[1] * e_dot[1]
        + damping[2] * e_dot[2] * e_dot[2]
    )


def stiffness_power(e, e_dot, stiffness, stiffness_min) -> float:
    """e' (K - K_min) e_dot for diagonal K, W (negative = drains the tank)."""
    return (
        e[0] * e_dot[0] * (stiffness[0] - stiffness_min[0])
        + e[1] * e_dot[1] * (stiffness[1] - stiffness_min[1])
        + e[2] * e_dot[2] * (stiffness[2] - stiffness_min[2])
    )


def tank_step(
    energy_J: float,
    e,
    e_dot,
    stiffness,
    stiffness_min,
    damping,
    dt: float,
    params: TankParams,
) -> TankStep:
    """One tick of the tank.

    Args:
        energy_J: T before the tick, J.
        e: position error x_d - x (3,), m.
        e_dot: velocity error -x_dot (3,), m/s.
        stiffness: K applied this tick (3,), N/m. Ignored (taken as K_min)
            when the tank is disabled.
        stiffness_min: K_min (3,), N/m.
        damping: D used this tick (3,), N s/m.
        dt: tick duration, s (>= 0).
        params: tank parameters.

    Returns:
        TankStep (energy after the tick, power, sigma, enabled).
    """
    sigma = tank_sigma(energy_J, params)
    p_damp = damping_power(e_dot, damping, sigma)
    if energy_J >= params.min_energy_J:
        power = stiffness_power(e, e_dot, stiffness, stiffness_min) + p_damp
        return TankStep(energy_J + power * dt, power, sigma, True)
    start = params.min_energy_J if params.floor_at_min else energy_J
    return TankStep(start + p_damp * dt, p_damp, sigma, False)


def tank_qp_rows(
    energy_J: float,
    e,
    e_dot,
    stiffness_min,
    damping,
    dt: float,
    params: TankParams,
) -> tuple[tuple[float, float, float], float, float]:
    """The two tank rows of the QP, as a' k >= lb_energy and a' k >= lb_power.

    From T + (e'(K - K_min) e_dot + sigma e_dot' D e_dot) dt >= T_min and
    e'(K - K_min) e_dot + sigma e_dot' D e_dot >= eta:

        a = e * e_dot (elementwise),
        lb_energy = -sigma e_dot' D e_dot + a' K_min + (T_min - T) / dt,
        lb_power  = -sigma e_dot' D e_dot + a' K_min + eta.

    Returns:
        (a, lb_energy, lb_power). With dt <= 0 the energy row is void
        (lb_energy = -inf).
    """
    sigma = tank_sigma(energy_J, params)
    a = (e[0] * e_dot[0], e[1] * e_dot[1], e[2] * e_dot[2])
    base = -damping_power(e_dot, damping, sigma) + (
        a[0] * stiffness_min[0] + a[1] * stiffness_min[1] + a[2] * stiffness_min[2]
    )
    lb_energy = base + (params.min_energy_J - energy_J) / dt if dt > 0.0 else -math.inf
    return a, lb_energy, base + params.power_limit_W
