"""Extended Kalman filter on Hunt-Crossley kappa, lam (and the surface, beta).

The state is a random walk (the tissue under a moving probe changes; the
follow-up work of the paper's first author used EKF/UKF variants on
Hunt-Crossley at fixed beta):

    x = [kappa / kappa_prior, lam / lam_prior, (ds in mm), (beta)]

with the surface offset ds (in the state when ``surface_walk_m_per_sqrt_s``
> 0: the surface is then s_in + ds, so a map's offset, or the drift of a
surface latched at first contact, is estimated too) and beta (when
``estimate_beta``). Measurement: the tissue force

    F = (kappa + lam eps_dot) (s_in + ds - z)^beta

linearised at the current state. Prediction adds the random-walk variance
of the time since the last update (a contact loss of a few seconds lets
the estimate move again at re-contact), capped at the prior variance.
Faulty samples and samples out of contact change nothing. Clipped
innovations and the covariance reset after ``clip_reset_s`` of them in a
row (those predicting a pulling force not counting), undone if the contact
ends before ``reset_confirm_s``: as the RLS
(:func:`~vic_drake.estimation.online.core.record_clip`).

With ``surface_from_slope`` (:func:`ekf_slope_step`) a fit of the tissue's
local slope under the moving tip (:mod:`vic_drake.estimation.online.slope`)
runs alongside: once valid, the surface it measures is the EKF's surface
input (when the caller gives none) in place of the surface latched at
first contact. Its state follows the EKF's in one list.
"""

from __future__ import annotations

import math

from vic_drake.estimation.online.core import (
    IN_CONTACT,
    N_UPDATES,
    S_PREV,
    T_UPDATE,
    Estimate,
    confirm_reset,
    gated_update,
    initial_state,
    make_estimate,
    prepare,
    state_size,
    unpack,
)
from vic_drake.estimation.online.params import OnlineEstimatorParams
from vic_drake.estimation.online.slope import (
    SURFACE,
    TARE,
    advance,
    slope_initial_state,
)

_MM = 1e-3


def ekf_layout(params: OnlineEstimatorParams) -> tuple[int, int | None, int | None]:
    """(state size, index of the surface offset or None, index of beta or None)."""
    n = 2
    i_s = i_b = None
    if params.surface_walk_m_per_sqrt_s > 0.0:
        i_s, n = n, n + 1
    if params.estimate_beta:
        i_b, n = n, n + 1
    return n, i_s, i_b


def _prior(params: OnlineEstimatorParams) -> tuple[list[float], list[float]]:
    """(x0, prior variance of each state)."""
    n, i_s, i_b = ekf_layout(params)
    x0 = [1.0, 1.0] + [0.0] * (n - 2)
    if i_b is not None:
        x0[i_b] = params.beta
    return x0, _variances(params, n, i_s, i_b)[0]


def ekf_initial_state(params: OnlineEstimatorParams) -> list[float]:
    """State at the prior (see the module docstring for the layout)."""
    x0, v = _prior(params)
    return initial_state(x0, v)


def _variances(
    params: OnlineEstimatorParams, n: int, i_s: int | None, i_b: int | None
) -> tuple[list[float], list[float]]:
    """(prior variance, random-walk variance per second) of each state."""
    p = params
    v = [p.prior_rel_std**2] * 2 + [0.0] * (n - 2)
    q = [p.kappa_walk_rel_per_sqrt_s**2, p.lam_walk_rel_per_sqrt_s**2] + v[2:]
    if i_s is not None:
        v[i_s] = (p.surface_prior_std_m / _MM) ** 2
        q[i_s] = (p.surface_walk_m_per_sqrt_s / _MM) ** 2
    if i_b is not None:
        v[i_b] = p.beta_prior_std**2
        q[i_b] = p.beta_walk_per_sqrt_s**2
    return v, q


def ekf_step(
    state,
    t: float,
    z: float,
    z_dot: float,
    force: float,
    surface_z: float,
    params: OnlineEstimatorParams,
    gate_phase: float | None = None,
) -> tuple[list[float], Estimate]:
    """One sample; arguments and result as :func:`~vic_drake.estimation.online.rls.rls_step`.

    ``surface_z_m`` of the estimate is the corrected surface s_in + ds.
    ``gate_phase``: as :func:`~vic_drake.estimation.online.core.prepare`'s.
    """
    p = params
    n, i_s, i_b = ekf_layout(p)
    aux, x, P, saved = unpack(state, n)
    beta = x[i_b] if i_b is not None else p.beta
    kappa_hat = x[0] * p.kappa_prior
    sample = prepare(aux, t, z, z_dot, force, surface_z, kappa_hat, beta, p, gate_phase)
    ds = x[i_s] * _MM if i_s is not None else 0.0
    if sample is None:
        aux[IN_CONTACT] = 0.0
        est = make_estimate(aux, x, P, p, aux[S_PREV] + ds, False)
        return aux + x + P + saved, est
    s_in, s_dot, touching, force = sample  # the force tared
    surface = s_in + ds
    eps = surface - z
    contact = touching and eps > p.min_penetration_m
    if contact:
        v0, walk = _variances(p, n, i_s, i_b)
        if not math.isnan(aux[T_UPDATE]):
            elapsed = t - aux[T_UPDATE]
            for i in range(n):
                k = i * (n + 1)
                P[k] = min(P[k] + walk[i] * elapsed, max(v0[i], P[k]))
        kappa, lam = x[0] * p.kappa_prior, x[1] * p.lam_prior
        eps_dot = s_dot - z_dot
        e_b = eps**beta
        stiff = kappa + lam * eps_dot
        predicted = stiff * e_b
        h = [p.kappa_prior * e_b, p.lam_prior * e_b * eps_dot] + [0.0] * (n - 2)
        if i_s is not None:
            h[i_s] = stiff * beta * eps ** (beta - 1.0) * _MM
        if i_b is not None:
            h[i_b] = predicted * math.log(eps)
        gated_update(aux, x, P, saved, t, h, force - predicted, stiff, v0, p)
        if i_b is not None:
            x[i_b] = min(max(x[i_b], 0.5), 3.0)
        aux[N_UPDATES] += 1.0
        aux[T_UPDATE] = t
    else:
        confirm_reset(aux, x, P, saved, t, None, False, p.reset_confirm_s)
    if i_s is not None:  # The offset as updated, or as put back.
        surface = s_in + x[i_s] * _MM
    aux[IN_CONTACT] = 1.0 if contact else 0.0
    return aux + x + P + saved, make_estimate(aux, x, P, p, surface, contact)


def ekf_slope_initial_state(params: OnlineEstimatorParams) -> list[float]:
    """The EKF's state followed by the slope fit's."""
    return ekf_initial_state(params) + slope_initial_state()


def ekf_slope_step(
    state,
    t: float,
    z: float,
    z_dot: float,
    force: float,
    surface_z: float,
    params: OnlineEstimatorParams,
    saturated: bool = False,
    at_force_bound: bool = False,
    dither_hz: float = 0.0,
) -> tuple[list[float], Estimate]:
    """:func:`ekf_step` on the slope fit's surface when ``surface_z`` is NaN
    (arguments and result as :func:`ekf_step`; ``saturated`` and
    ``at_force_bound``: the controller's stiffness and force at their
    bounds, and ``dither_hz`` its dither's frequency, for the fit,
    :func:`~vic_drake.estimation.online.slope.slope_step`).

    The fit and the EKF see the same samples, so the fit's contact gate
    serves both, its tare included (the gate entries of the EKF's part of
    the state stay unused)."""
    p = params
    if type(state) is not list:  # (slices of an array would be views)
        state = list(state)
    size = state_size(ekf_layout(p)[0])
    fit = state[size:]
    phase = advance(
        fit, t, z, z_dot, force, p, state[S_PREV], saturated, at_force_bound,
        dither_hz,
    )  # fmt: skip
    if math.isnan(surface_z):
        surface_z = fit[SURFACE]
    force -= fit[TARE]
    ekf_state, est = ekf_step(state[:size], t, z, z_dot, force, surface_z, p, phase)
    return ekf_state + fit, est


__all__ = [
    "ekf_slope_initial_state",
    "ekf_slope_step",
    "ekf_initial_state",
    "ekf_layout",
    "ekf_step",
]
