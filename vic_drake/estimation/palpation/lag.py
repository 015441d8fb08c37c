"""The sensor lag of the force behind the position, found by fit quality.

The force sample of time t belongs to the position of time t - lag. The lag
is a property of the sensor chain, so it is found once per log
(:func:`estimate_lag`): each force sample is paired with the (smoothed)
kinematics one candidate lag earlier, on a grid of one sample period over
[0, max_lag_s]; the reference model (Hunt-Crossley at the paper's beta, with
the stated m_I) is refitted, and the lag with the smallest RMS residual wins
(Brent refinement between grid neighbours). The approach transient (first
second of contact) is left out of this search. All models are then compared
at that one lag.

What identifies the lag: to first order a time shift of the force is a phase
lead that the viscous term absorbs (lag and lam trade off), to second order
it adds tau^2/2 F_ddot, an inertia-like term of about k_lin tau^2 / 2 kg that
the fixed m_I cannot absorb. The search thus finds the lag at which the data
are consistent with the known indenter mass; refitting m_I as a free
parameter leaves the residual nearly flat in lag. The signal grows with the
palpation frequency squared, so slow palpations identify the lag poorly
(:meth:`LagProfile.flat_range`; docs/decisions.md, "Palpation sensor lag").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation.data import (
    DEFAULT_INDENTER_MASS_KG,
    DEFAULT_MIN_FORCE_N,
    DEFAULT_MIN_PENETRATION_M,
    DEFAULT_SPIKE_SIGMA,
    PalpationData,
    kinematics,
    spike_mask,
)
from vic_drake.estimation.palpation.fits import (
    MIN_CONTACT_SAMPLES,
    _check_beta,
    _check_mass,
    _fit_hc,
    _Problem,
)
from vic_drake.estimation.signals import DEFAULT_DERIVATIVE_WINDOW_S, median_period
from vic_drake.paper import BEST_BETA

DEFAULT_MAX_LAG_S = 0.2
"""Upper end of the lag search, s."""

DEFAULT_LAG_SETTLE_S = 1.0
"""Approach transient left out of the lag search, s (see :func:`lag_profile`)."""


@dataclass(frozen=True)
class LagProfile:
    """RMS residual of the reference fit for each candidate lag.

    Attributes:
        lags_s: (k,) candidate lags, s. rms_N: (k,) RMS residual, N.
        lag_s: the refined minimiser. beta: reference exponent used.
    """

    lags_s: np.ndarray
    rms_N: np.ndarray
    lag_s: float
    beta: float

    def flat_range(self, tolerance: float = 0.01) -> tuple[float, float]:
        """Lags whose residual is within ``tolerance`` (relative) of the best.

        A wide range means the lag is poorly identified by this log (see the
        module docstring); the contiguous range around the minimiser is given.
        """
        limit = (1.0 + tolerance) * float(np.min(self.rms_N))
        best = int(np.argmin(self.rms_N))
        lo = hi = best
        while lo > 0 and self.rms_N[lo - 1] <= limit:
            lo -= 1
        while hi < self.rms_N.size - 1 and self.rms_N[hi + 1] <= limit:
            hi += 1
        return float(self.lags_s[lo]), float(self.lags_s[hi])


def lag_profile(
    data: PalpationData,
    max_lag_s: float = DEFAULT_MAX_LAG_S,
    *,
    beta: float = BEST_BETA,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
    settle_s: float = DEFAULT_LAG_SETTLE_S,
) -> LagProfile:
    """Reference-fit RMS residual over lags 0, dt, 2 dt, ... max_lag_s.

    For each candidate the force samples are paired with the smoothed
    kinematics ``lag`` earlier (as
    :func:`~vic_drake.estimation.palpation.data.shift` does), the contact samples
    are reselected and Hunt-Crossley at ``beta`` is refitted.
    Force samples in the first ``max_lag_s`` of the log are left out for
    every candidate, so all candidates are scored on the same force samples
    (the contact test on penetration still follows the lag).

    The approach is left out too: force samples within ``settle_s`` of the
    first pressing sample (force > ``min_force_N``), capped at a quarter of
    the in-contact time. The rig's palpations start at the surface and sink
    to the working depth over the first cycle while the tissue relaxes, which
    Hunt-Crossley does not model, and which can pull the minimiser of a slow
    palpation to 0 (docs/decisions.md, "Approach transient in the lag
    search").
    """
    max_lag_s = float(max_lag_s)
    if not (math.isfinite(max_lag_s) and max_lag_s >= 0.0):
        raise VicDrakeError(f"max_lag_s must be finite and >= 0; got {max_lag_s!r}")
    if max_lag_s > 0.5 * data.duration_s:
        raise VicDrakeError(
            f"max_lag_s = {max_lag_s} s is more than half the {data.duration_s:.3f} s log"
        )
    beta = _check_beta(beta)
    mass = _check_mass(indenter_mass_kg)
    dt = median_period(data.t_s)
    lags = dt * np.arange(int(np.floor(max_lag_s / dt + 1e-9)) + 1)
    kin = kinematics(data, window_s=derivative_window_s)
    # Force samples whose position is inside the log for every candidate.
    span = data.t_s >= data.t_s[0] + max_lag_s
    if spike_sigma is not None:
        span &= spike_mask(data.force_N, sigma=spike_sigma)
    span &= data.force_N > min_force_N
    if settle_s > 0.0 and span.any():
        pressing = data.t_s[data.force_N > min_force_N]
        settle = min(float(settle_s), 0.25 * (pressing[-1] - pressing[0]))
        span &= data.t_s >= pressing[0] + settle

    def score(lag: float) -> float:
        t_pos = data.t_s - lag
        eps = np.interp(t_pos, data.t_s, kin.eps_m)
        mask = span & (eps > min_penetration_m)
        mask &= np.interp(t_pos, data.t_s, kin.valid.astype(float)) > 0.999
        n = int(mask.sum())
        if n < MIN_CONTACT_SAMPLES:
            raise VicDrakeError(
                f"only {n} in-contact samples (penetration > "
                f"{min_penetration_m * 1e3:g} mm and force > {min_force_N:g} N); "
                f"a fit needs at least {MIN_CONTACT_SAMPLES}"
            )
        p = _Problem(
            eps,
            np.interp(t_pos, data.t_s, kin.eps_dot_m_per_s),
            np.interp(t_pos, data.t_s, kin.z_ddot_m_per_s2),
            data.force_N,
            mask,
        )
        return _fit_hc(p, beta, mass).rms_N

    rms = np.array([score(lag) for lag in lags])
    best = int(np.argmin(rms))
    lag = float(lags[best])
    if lags.size > 1:
        # Continuous refinement between the grid neighbours (Brent).
        lo, hi = lags[max(best - 1, 0)], lags[min(best + 1, lags.size - 1)]
        res = minimize_scalar(
            score, bounds=(lo, hi), method="bounded", options={"xatol": 1e-5}
        )
        if res.fun < rms[best]:
            lag = float(res.x)
    return LagProfile(lags_s=lags, rms_N=rms, lag_s=lag, beta=beta)


def estimate_lag(
    data: PalpationData,
    max_lag_s: float = DEFAULT_MAX_LAG_S,
    *,
    beta: float = BEST_BETA,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    settle_s: float = DEFAULT_LAG_SETTLE_S,
) -> float:
    """Sensor lag of the force behind the position, s (>= 0).

    The lag in [0, max_lag_s] minimising the RMS residual of the reference
    Hunt-Crossley fit (see :func:`lag_profile` and the module docstring).
    """
    return lag_profile(
        data,
        max_lag_s,
        beta=beta,
        indenter_mass_kg=indenter_mass_kg,
        derivative_window_s=derivative_window_s,
        settle_s=settle_s,
    ).lag_s
