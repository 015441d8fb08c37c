"""Fig. 3: residual against palpation time and its exponential fit."""

import numpy as np
import pytest

from vic_drake.estimation.palpation import fit_exponential, residual_vs_palpation_time

from .synthetic import synthetic_palpation


def test_exponential_fit_recovers_parameters():
    t = np.linspace(0.5, 30.0, 40)
    fit = fit_exponential(t, 0.1 * np.exp(-t / 4.0) + 0.02)
    assert fit.a == pytest.approx(0.1, rel=1e-4)
    assert fit.tau_s == pytest.approx(4.0, rel=1e-4)
    assert fit.c == pytest.approx(0.02, rel=1e-4)


def test_exponential_fit_is_robust_to_one_outlier():
    t = np.linspace(0.5, 30.0, 40)
    r = 0.1 * np.exp(-t / 4.0) + 0.02
    r[1] = 0.0  # One window that happened to generalise unusually well.
    fit = fit_exponential(t, r)
    assert fit.tau_s == pytest.approx(4.0, rel=0.1)
    assert fit.c == pytest.approx(0.02, rel=0.05)


def test_residual_decreases_with_palpation_time():
    data = synthetic_palpation(noise_N=0.2, duration_s=20.0, seed=5)
    curve = residual_vs_palpation_time(data)
    assert curve.window_s[0] == 0.5
    assert curve.window_s[-1] == pytest.approx(data.duration_s, abs=0.01)
    # The whole-log fit minimises the whole-log residual.
    assert curve.relative[-1] == pytest.approx(curve.relative.min(), rel=1e-9)
    assert curve.relative[0] > curve.relative[-1]
    assert curve.kappa[-1] == pytest.approx(4000.0, rel=0.05)
