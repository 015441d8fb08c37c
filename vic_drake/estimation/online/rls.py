"""Recursive least squares with forgetting on Hunt-Crossley kappa, lam at fixed beta.

At fixed beta the tissue force is linear in (kappa, lam) (paper eq. 4, as
the offline fit; Haddadi and Hashtrudi-Zaad, T-RO 2012):

    F = [eps^beta, eps^beta eps_dot] . [kappa, lam]

Each sample in contact is weighted by 1 / noise_std_N^2 and old samples
fade with the forgetting factor exp(-dt / memory_s): the covariance is
divided by it before each update. A direction the data does not excite
(lam, when the probe barely moves) would then grow without bound
(wind-up); each variance is capped at its prior value instead. Out of
contact, and on a faulty sample, nothing is forgotten and nothing learnt:
the estimate is held. Innovations beyond ``gate_sigma`` are clipped (spikes);
after ``clip_reset_s`` of clipped updates in a row the covariance returns to
the prior (:func:`~vic_drake.estimation.online.core.record_clip`), updates
where the estimate predicts a pulling force (kappa + lam eps_dot <= 0, out of
the model's domain) not counting; a reset that contact does not confirm
(``reset_confirm_s``) is undone when the contact ends. Shared
bookkeeping (faults, surface, contact) in
:mod:`vic_drake.estimation.online.core`.

``rls_initial_state(params)`` and ``rls_step(state, t, z, z_dot, force,
surface_z, params)`` are pure: the same functions serve the LeafSystem, the
replay of the real logs and the tests.
"""

from __future__ import annotations

import math

from vic_drake.estimation.online.core import (
    IN_CONTACT,
    N_UPDATES,
    S_PREV,
    T_UPDATE,
    Estimate,
    cap_variances,
    confirm_reset,
    gated_update,
    initial_state,
    make_estimate,
    prepare,
    unpack,
)
from vic_drake.estimation.online.params import OnlineEstimatorParams

RLS_SIZE = 2  # kappa / kappa_prior, lam / lam_prior


def rls_initial_state(params: OnlineEstimatorParams) -> list[float]:
    """State at the prior: x = (1, 1), P = prior_rel_std^2 I."""
    v = params.prior_rel_std**2
    return initial_state([1.0, 1.0], [v, v])


def rls_step(
    state,
    t: float,
    z: float,
    z_dot: float,
    force: float,
    surface_z: float,
    params: OnlineEstimatorParams,
) -> tuple[list[float], Estimate]:
    """One sample.

    Args:
        state: from :func:`rls_initial_state` or the previous step (not
            modified).
        t: time, s. z: tip height, m. z_dot: tip velocity along z, m/s.
        force: tissue force on the probe along +z, N (positive = the body
            pushes the probe up: minus the sensor's z force).
        surface_z: tissue surface height under the probe, m; NaN when not
            known (latched at first contact, see the core module).
        params: settings (``method`` is not read: this is the RLS).

    Returns:
        (new state, Estimate).
    """
    aux, x, P, saved = unpack(state, RLS_SIZE)
    p = params
    sample = prepare(
        aux, t, z, z_dot, force, surface_z, x[0] * p.kappa_prior, p.beta, p
    )
    if sample is None:
        aux[IN_CONTACT] = 0.0
        return aux + x + P + saved, make_estimate(aux, x, P, p, aux[S_PREV], False)
    s_in, s_dot, touching, force = sample  # the force tared
    eps = s_in - z
    contact = touching and eps > p.min_penetration_m
    if contact:
        e_b = eps**p.beta
        eps_dot = s_dot - z_dot
        h = [p.kappa_prior * e_b, p.lam_prior * e_b * eps_dot]
        if not math.isnan(aux[T_UPDATE]):
            forget = math.exp(-min(t - aux[T_UPDATE], p.max_gap_s) / p.memory_s)
            P = [v / forget for v in P]
            cap = p.prior_rel_std**2
            cap_variances(P, [cap, cap])
        innovation = force - (h[0] * x[0] + h[1] * x[1])
        # Stiffness of the estimate at this rate (<= 0: it predicts a pull).
        stiff = p.kappa_prior * x[0] + p.lam_prior * x[1] * eps_dot
        prior_var = [p.prior_rel_std**2] * RLS_SIZE
        gated_update(aux, x, P, saved, t, h, innovation, stiff, prior_var, p)
        aux[N_UPDATES] += 1.0
        aux[T_UPDATE] = t
    else:
        confirm_reset(aux, x, P, saved, t, None, False, p.reset_confirm_s)
    aux[IN_CONTACT] = 1.0 if contact else 0.0
    return aux + x + P + saved, make_estimate(aux, x, P, p, s_in, contact)


__all__ = ["RLS_SIZE", "rls_initial_state", "rls_step"]
