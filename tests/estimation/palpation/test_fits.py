"""Least-squares fits: analytic recovery, the relative residual, bad inputs."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation import (
    PalpationData,
    fit_hunt_crossley,
    fit_hunt_crossley_with_mass,
    fit_kelvin_voigt,
)
from vic_drake.tissue import hunt_crossley_force

from .synthetic import polynomial_palpation, synthetic_palpation


@pytest.mark.parametrize("mass_kg", [0.0, 0.081, 0.5])
def test_hunt_crossley_exact_recovery(mass_kg):
    kappa, lam, beta = 3500.0, 25000.0, 1.35
    data = polynomial_palpation(
        lambda e, ed, edd: hunt_crossley_force(e, ed, kappa, lam, beta) + mass_kg * edd
    )  # z_ddot = -eps_ddot, so F_sensor = F_tissue - m z_ddot = F_tissue + m eps_ddot.
    fit = fit_hunt_crossley(data, beta, indenter_mass_kg=mass_kg, spike_sigma=None)
    assert fit.kappa == pytest.approx(kappa, rel=1e-7)
    assert fit.lam == pytest.approx(lam, rel=1e-6)
    assert fit.rms_N < 1e-8
    assert fit.relative < 1e-8
    assert fit.beta == beta
    assert fit.indenter_mass_kg == mass_kg


def test_kelvin_voigt_exact_recovery():
    data = polynomial_palpation(lambda e, ed, edd: 800.0 * e + 40.0 * ed + 0.081 * edd)
    fit = fit_kelvin_voigt(data, spike_sigma=None)
    assert fit.k == pytest.approx(800.0, rel=1e-8)
    assert fit.d == pytest.approx(40.0, rel=1e-6)
    assert fit.rms_N < 1e-9


def test_relative_residual_definition():
    # A force that the model cannot express: the residual is known exactly
    # once the model columns are orthogonal to it (checked via lstsq here).
    data = polynomial_palpation(lambda e, ed, edd: 1000.0 * e**1.0)
    fit = fit_hunt_crossley(data, 1.35, indenter_mass_kg=0.0, spike_sigma=None)
    eps = data.penetration_m
    mask = (eps > 0.5e-3) & (data.force_N > 0.5)
    y = data.force_N[mask]
    pred = hunt_crossley_force(
        eps[mask], np.gradient(eps, data.t_s)[mask], fit.kappa, fit.lam, 1.35
    )
    rms = np.sqrt(np.mean((y - pred) ** 2))
    assert fit.rms_N == pytest.approx(rms, rel=1e-3)
    assert fit.relative == pytest.approx(fit.rms_N / np.sqrt(np.mean(y**2)), rel=1e-12)
    assert fit.n_samples == mask.sum()


def test_fit_bad_inputs():
    data = synthetic_palpation()
    with pytest.raises(VicDrakeError, match=r"\(0, 3\]"):
        fit_hunt_crossley(data, 0.0)
    with pytest.raises(VicDrakeError, match=r"\(0, 3\]"):
        fit_hunt_crossley(data, 3.5)
    with pytest.raises(VicDrakeError, match="indenter_mass_kg"):
        fit_hunt_crossley(data, 1.35, indenter_mass_kg=-1.0)
    lifted = PalpationData(
        data.t_s, data.z_m + 0.02, data.force_N * 0.0, data.surface_z_m
    )
    with pytest.raises(VicDrakeError, match="in-contact samples"):
        fit_hunt_crossley(lifted, 1.35)
    with pytest.raises(VicDrakeError, match="in-contact samples"):
        fit_kelvin_voigt(lifted)


def test_mass_estimate_on_rich_motion():
    data = synthetic_palpation(mass_kg=0.3, freq_hz=4.0, eps_amp_m=0.003, noise_N=0.005)
    est = fit_hunt_crossley_with_mass(data, 1.35)
    assert est.indenter_mass_kg == pytest.approx(0.3, abs=0.03)


def test_fit_is_linear_in_force_and_ignores_the_time_origin():
    data = synthetic_palpation(noise_N=0.02, duration_s=4.0)
    base = fit_hunt_crossley(data, 1.35, indenter_mass_kg=0.0)
    doubled = PalpationData(
        data.t_s + 1e4, data.z_m, 2.0 * data.force_N, data.surface_z_m
    )
    fit = fit_hunt_crossley(doubled, 1.35, indenter_mass_kg=0.0)
    assert fit.kappa == pytest.approx(2.0 * base.kappa, rel=1e-6)
    assert fit.lam == pytest.approx(2.0 * base.lam, rel=1e-5)
    assert fit.relative == pytest.approx(base.relative, rel=1e-5)
