"""Table I: Kelvin-Voigt against Hunt-Crossley at several beta, and the beta sweep.

:func:`compare_models` runs the whole offline pipeline on one raw log (as
``vic-drake fit-palpation`` does): sensor lag
(:func:`~vic_drake.estimation.palpation.lag.lag_profile`), alignment
(:func:`~vic_drake.estimation.palpation.data.shift`), the Kelvin-Voigt fit,
Hunt-Crossley at the paper's exponents (:data:`vic_drake.paper.TABLE_I_BETAS`)
and :func:`sweep_beta` over [1.0, 2.0].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from vic_drake.estimation.palpation.data import (
    DEFAULT_INDENTER_MASS_KG,
    DEFAULT_MIN_FORCE_N,
    DEFAULT_MIN_PENETRATION_M,
    DEFAULT_SPIKE_SIGMA,
    PalpationData,
    shift,
)
from vic_drake.estimation.palpation.fits import (
    HuntCrossleyFit,
    KelvinVoigtFit,
    _check_beta,
    _check_mass,
    _fit_hc,
    _problem,
    fit_hunt_crossley,
    fit_kelvin_voigt,
)
from vic_drake.estimation.palpation.lag import (
    DEFAULT_MAX_LAG_S,
    LagProfile,
    lag_profile,
)
from vic_drake.estimation.signals import DEFAULT_DERIVATIVE_WINDOW_S
from vic_drake.paper import (
    PAPER_TABLE_I_HUNT_CROSSLEY,
    PAPER_TABLE_I_KELVIN_VOIGT,
    TABLE_I_BETAS,
)

BETA_RANGE = (1.0, 2.0)
"""Range of the beta sweep."""

BETA_GRID_STEP = 0.05
"""Step of the beta sweep's grid."""

PAPER_TABLE_I = {
    "kelvin_voigt": PAPER_TABLE_I_KELVIN_VOIGT,
    **PAPER_TABLE_I_HUNT_CROSSLEY,
}
"""The paper's Table I keyed like :class:`ModelComparison` ("kelvin_voigt" and
beta), for plots next to ours; the numbers live in :mod:`vic_drake.paper`."""


@dataclass(frozen=True)
class BetaSweep:
    """Hunt-Crossley fits over a grid of beta.

    Attributes:
        betas: (k,) grid. rms_N, relative: (k,) residuals per beta.
        best_beta: refined minimiser of rms_N in the grid's range.
        best_fit: the fit at best_beta.
    """

    betas: np.ndarray
    rms_N: np.ndarray
    relative: np.ndarray
    best_beta: float
    best_fit: HuntCrossleyFit


def sweep_beta(
    data: PalpationData,
    betas=None,
    *,
    refine: bool = True,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
) -> BetaSweep:
    """Fits Hunt-Crossley for each beta (default 1.0, 1.05, ..., 2.0).

    With ``refine`` the grid minimiser is polished by a bounded scalar
    search (Brent, xatol 1e-4) between its grid neighbours.
    """
    if betas is None:
        lo, hi = BETA_RANGE
        betas = np.round(np.arange(lo, hi + 0.5 * BETA_GRID_STEP, BETA_GRID_STEP), 10)
    betas = np.array([_check_beta(b) for b in np.atleast_1d(betas)])
    mass = _check_mass(indenter_mass_kg)
    p = _problem(
        data,
        derivative_window_s=derivative_window_s,
        min_penetration_m=min_penetration_m,
        min_force_N=min_force_N,
        spike_sigma=spike_sigma,
    )
    fits = [_fit_hc(p, b, mass) for b in betas]
    rms = np.array([f.rms_N for f in fits])
    rel = np.array([f.relative for f in fits])
    best = int(np.argmin(rms))
    best_fit = fits[best]
    if refine and betas.size >= 3:
        order = np.sort(betas)
        k = int(np.searchsorted(order, betas[best]))
        lo = order[max(k - 1, 0)]
        hi = order[min(k + 1, order.size - 1)]
        if hi > lo:
            res = minimize_scalar(
                lambda b: _fit_hc(p, float(b), mass).rms_N,
                bounds=(lo, hi),
                method="bounded",
                options={"xatol": 1e-4},
            )
            candidate = _fit_hc(p, float(res.x), mass)
            if candidate.rms_N < best_fit.rms_N:
                best_fit = candidate
    return BetaSweep(
        betas=betas, rms_N=rms, relative=rel, best_beta=best_fit.beta, best_fit=best_fit
    )


@dataclass(frozen=True)
class ModelComparison:
    """Table I: Kelvin-Voigt and Hunt-Crossley at several beta on one log.

    Attributes:
        lag_s: the lag removed before fitting, s.
        kelvin_voigt: the KV fit.
        hunt_crossley: beta -> HC fit (in the order given).
        sweep: the beta sweep over [1.0, 2.0], or None.
        lag_profile: the lag search, or None when the lag was given.
    """

    lag_s: float
    kelvin_voigt: KelvinVoigtFit
    hunt_crossley: dict[float, HuntCrossleyFit]
    sweep: BetaSweep | None = None
    lag_profile: LagProfile | None = None

    @property
    def best_beta(self) -> float | None:
        return None if self.sweep is None else self.sweep.best_beta


def compare_models(
    data: PalpationData,
    betas=TABLE_I_BETAS,
    *,
    lag_s: float | None = None,
    max_lag_s: float = DEFAULT_MAX_LAG_S,
    sweep: bool = True,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    progress=None,
) -> ModelComparison:
    """Lag estimation, alignment, KV and HC fits, beta sweep, on a raw log.

    Args:
        data: the palpation as logged (force lagging position).
        betas: exponents to report.
        lag_s: the lag to remove; None estimates it (:func:`estimate_lag`).
        max_lag_s: lag search range [0, max_lag_s].
        sweep: also run :func:`sweep_beta` over [1.0, 2.0].
        progress: optional callable(str) for progress messages.
    """
    say = progress or (lambda _msg: None)
    betas = [_check_beta(b) for b in betas]
    profile = None
    if lag_s is None:
        say(f"estimating the sensor lag over [0, {max_lag_s:g}] s")
        profile = lag_profile(
            data,
            max_lag_s,
            indenter_mass_kg=indenter_mass_kg,
            derivative_window_s=derivative_window_s,
        )
        lag_s = profile.lag_s
    aligned = shift(data, lag_s)
    kw = dict(
        indenter_mass_kg=indenter_mass_kg, derivative_window_s=derivative_window_s
    )
    say("fitting Kelvin-Voigt and Hunt-Crossley")
    kv = fit_kelvin_voigt(aligned, **kw)
    hc = {b: fit_hunt_crossley(aligned, b, **kw) for b in betas}
    result_sweep = None
    if sweep:
        say("sweeping beta over [1.0, 2.0]")
        result_sweep = sweep_beta(aligned, **kw)
    return ModelComparison(
        lag_s=float(lag_s),
        kelvin_voigt=kv,
        hunt_crossley=hc,
        sweep=result_sweep,
        lag_profile=profile,
    )
