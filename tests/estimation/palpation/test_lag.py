"""The sensor-lag search on synthetic palpations with a known lag."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation import (
    PalpationData,
    estimate_lag,
    fit_hunt_crossley,
    lag_profile,
    shift,
)

from .synthetic import synthetic_palpation


def test_recovers_kappa_lambda_from_noisy_lagged_palpation():
    kappa, lam, lag = 4000.0, 20000.0, 0.056
    data = synthetic_palpation(kappa=kappa, lam=lam, lag_s=lag, noise_N=0.03, seed=3)
    lag_hat = estimate_lag(data)
    assert lag_hat == pytest.approx(lag, abs=0.002)
    fit = fit_hunt_crossley(shift(data, lag_hat), 1.35)
    assert fit.kappa == pytest.approx(kappa, rel=0.02)
    assert fit.lam == pytest.approx(lam, rel=0.02)
    # The residual is the noise, partly averaged away by the fractional-lag
    # interpolation of the shift (two neighbours weighted a, 1 - a: the
    # noise's RMS shrinks by sqrt(a^2 + (1 - a)^2) >= 0.71).
    assert 0.03 * 0.65 < fit.rms_N < 0.03 * 1.1


def test_lag_profile_is_minimal_at_the_true_lag():
    data = synthetic_palpation(lag_s=0.03, noise_N=0.01, duration_s=6.0)
    prof = lag_profile(data, 0.1)
    assert prof.lags_s[0] == 0.0 and prof.lags_s[-1] <= 0.1 + 1e-12
    assert abs(prof.lags_s[np.argmin(prof.rms_N)] - 0.03) <= 0.0021
    lo, hi = prof.flat_range(0.01)
    assert lo <= prof.lags_s[np.argmin(prof.rms_N)] <= hi
    assert prof.flat_range(1e6) == (0.0, prof.lags_s[-1])
    with pytest.raises(VicDrakeError, match="max_lag_s"):
        lag_profile(data, -0.1)


def test_lag_search_ignores_the_approach_transient():
    data = synthetic_palpation(lag_s=0.04, noise_N=0.01, duration_s=8.0)
    force = data.force_N.copy()
    early = data.t_s < 0.9
    force[early] = 1.0 + 3.0 * force[early]  # An unmodelled approach phase.
    corrupt = PalpationData(data.t_s, data.z_m, force, data.surface_z_m)
    assert estimate_lag(corrupt) == pytest.approx(0.04, abs=0.002)
    assert estimate_lag(corrupt, settle_s=0.0) != pytest.approx(0.04, abs=0.002)
