"""Palpation fits: analytic cases, synthetic recovery, and the real logs."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation import (
    PalpationData,
    compare_models,
    estimate_lag,
    fit_exponential,
    fit_hunt_crossley,
    fit_hunt_crossley_with_mass,
    fit_kelvin_voigt,
    residual_vs_palpation_time,
    shift,
    shift_signal,
    smoothed_derivatives,
    sweep_beta,
)
from vic_drake.estimation.palpation import lag_profile
from vic_drake.realdata import read_bag
from vic_drake.tissue import hunt_crossley_force

SURFACE_Z_M = -0.05
PALPATION_LOGS = ("test_soft_1hz", "test_soft_2hz", "test_soft_25hz")


def synthetic_palpation(
    *,
    kappa=4000.0,
    lam=20000.0,
    beta=1.35,
    mass_kg=0.081,
    lag_s=0.0,
    noise_N=0.0,
    freq_hz=1.5,
    duration_s=12.0,
    eps_mean_m=0.008,
    eps_amp_m=0.002,
    jitter_s=2e-4,
    seed=0,
):
    """Sinusoidal palpation of an HC tissue as the rig would log it.

    The sensor reads F_tissue - m z_ddot, late by ``lag_s``, with white noise;
    timestamps are 2 ms apart with uniform jitter of +-``jitter_s``.
    """
    rng = np.random.default_rng(seed)
    n = int(duration_s / 0.002)
    t = 0.002 * np.arange(n) + rng.uniform(-jitter_s, jitter_s, n)
    t[0] = 0.0
    w = 2 * np.pi * freq_hz

    def eps_of(tt):
        return eps_mean_m + eps_amp_m * np.sin(w * tt)

    def force_of(tt):
        eps = eps_of(tt)
        eps_dot = eps_amp_m * w * np.cos(w * tt)
        z_ddot = eps_amp_m * w**2 * np.sin(w * tt)  # z = s - eps.
        return hunt_crossley_force(eps, eps_dot, kappa, lam, beta) - mass_kg * z_ddot

    force = force_of(t - lag_s) + noise_N * rng.standard_normal(n)
    return PalpationData(
        t_s=t, z_m=SURFACE_Z_M - eps_of(t), force_N=force, surface_z_m=SURFACE_Z_M
    )


def polynomial_palpation(force_fn, n=2000, dt=0.002):
    """Uniform samples of a cubic z(t) (Savitzky-Golay derivatives are exact)."""
    t = dt * np.arange(n)
    T = t[-1]
    eps = 0.002 + 0.006 * (t / T) + 0.003 * (t / T) ** 2 - 0.002 * (t / T) ** 3
    eps_dot = (0.006 + 0.006 * (t / T) - 0.006 * (t / T) ** 2) / T
    eps_ddot = (0.006 - 0.012 * (t / T)) / T**2
    force = force_fn(eps, eps_dot, eps_ddot)
    return PalpationData(
        t_s=t, z_m=SURFACE_Z_M - eps, force_N=force, surface_z_m=SURFACE_Z_M
    )


# --- signals -----------------------------------------------------------------


def test_smoothed_derivatives_of_sinusoid_on_uneven_timestamps():
    rng = np.random.default_rng(1)
    t = 0.002 * np.arange(5000) + rng.uniform(-2e-4, 2e-4, 5000)
    w = 2 * np.pi * 2.5
    x = 0.002 * np.sin(w * t)
    xs, xd, xdd = smoothed_derivatives(t, x)
    inner = slice(50, -50)
    np.testing.assert_allclose(xs[inner], x[inner], atol=0.002 * 2e-3)
    np.testing.assert_allclose(
        xd[inner], 0.002 * w * np.cos(w * t[inner]), atol=0.002 * w * 1e-2
    )
    np.testing.assert_allclose(
        xdd[inner], -0.002 * w**2 * np.sin(w * t[inner]), atol=0.002 * w**2 * 3e-2
    )


def test_smoothed_derivatives_exact_for_cubic():
    t = 0.002 * np.arange(400)
    x = 1.0 + 2.0 * t - 3.0 * t**2 + 0.5 * t**3
    xs, xd, xdd = smoothed_derivatives(t, x)
    np.testing.assert_allclose(xs, x, atol=1e-10)
    np.testing.assert_allclose(xd, 2.0 - 6.0 * t + 1.5 * t**2, atol=1e-8)
    np.testing.assert_allclose(xdd, -6.0 + 3.0 * t, atol=1e-6)


def test_smoothed_derivatives_bad_input():
    with pytest.raises(VicDrakeError, match="increase"):
        smoothed_derivatives([0.0, 0.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(VicDrakeError, match="window"):
        smoothed_derivatives(0.002 * np.arange(10), np.zeros(10))


def test_shift_signal_advances_a_ramp():
    t = np.array([0.0, 0.0021, 0.0039, 0.0061, 0.008])
    out = shift_signal(t, 3.0 * t, 0.002)
    np.testing.assert_allclose(out[:3], 3.0 * (t[:3] + 0.002))
    assert np.isnan(out[3:]).all()  # t + lag past the last sample.


# --- PalpationData -------------------------------------------------------------


def test_from_frame_negates_the_sensor_force():
    df = pd.DataFrame(
        {
            "t_s": [0.0, 0.002, 0.004],
            "surface_z_m": [-0.05] * 3,
            "z_target_m": [-0.06] * 3,
            "z_m": [-0.05, -0.051, -0.052],
            "vz_m_per_s": [0.0] * 3,
            "force_z_N": [-1.0, -2.0, -3.0],
        }
    )
    data = PalpationData.from_frame(df)
    np.testing.assert_allclose(data.force_N, [1.0, 2.0, 3.0])
    assert data.surface_z_m == -0.05
    np.testing.assert_allclose(data.penetration_m, [0.0, 0.001, 0.002], atol=1e-15)
    with pytest.raises(VicDrakeError, match="palpation"):
        PalpationData.from_frame(df.drop(columns="force_z_N"))


def test_palpation_data_validation():
    with pytest.raises(VicDrakeError, match="force_N"):
        PalpationData(t_s=[0.0, 1.0], z_m=[0.0, 0.0], force_N=[0.0], surface_z_m=0.0)
    with pytest.raises(VicDrakeError, match="non-finite"):
        PalpationData(
            t_s=[0.0, 1.0], z_m=[0.0, np.nan], force_N=[0, 0], surface_z_m=0.0
        )
    with pytest.raises(VicDrakeError, match="increase"):
        PalpationData(t_s=[1.0, 0.0], z_m=[0.0, 0.0], force_N=[0, 0], surface_z_m=0.0)


# --- least squares, analytic ----------------------------------------------------


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


# --- synthetic recovery -----------------------------------------------------------


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


def test_sweep_finds_the_generating_beta():
    data = synthetic_palpation(kappa=2000.0, lam=15000.0, beta=1.2, noise_N=0.02)
    sweep = sweep_beta(data)
    assert sweep.betas[0] == 1.0 and sweep.betas[-1] == 2.0 and sweep.betas.size == 21
    assert sweep.best_beta == pytest.approx(1.2, abs=0.01)
    assert sweep.best_fit.rms_N <= sweep.rms_N.min() + 1e-12


def test_mass_estimate_on_rich_motion():
    data = synthetic_palpation(mass_kg=0.3, freq_hz=4.0, eps_amp_m=0.003, noise_N=0.005)
    est = fit_hunt_crossley_with_mass(data, 1.35)
    assert est.indenter_mass_kg == pytest.approx(0.3, abs=0.03)


def test_exponential_fit_recovers_parameters():
    t = np.linspace(0.5, 30.0, 40)
    fit = fit_exponential(t, 0.1 * np.exp(-t / 4.0) + 0.02)
    assert fit.a == pytest.approx(0.1, rel=1e-4)
    assert fit.tau_s == pytest.approx(4.0, rel=1e-4)
    assert fit.c == pytest.approx(0.02, rel=1e-4)


def test_residual_decreases_with_palpation_time():
    data = synthetic_palpation(noise_N=0.2, duration_s=20.0, seed=5)
    curve = residual_vs_palpation_time(data)
    assert curve.window_s[0] == 0.5
    assert curve.window_s[-1] == pytest.approx(data.duration_s, abs=0.01)
    # The whole-log fit minimises the whole-log residual.
    assert curve.relative[-1] == pytest.approx(curve.relative.min(), rel=1e-9)
    assert curve.relative[0] > curve.relative[-1]
    assert curve.kappa[-1] == pytest.approx(4000.0, rel=0.05)


# --- the real palpation logs -----------------------------------------------------


@pytest.fixture(scope="module")
def real_logs(data_dir):
    return {
        name: PalpationData.from_frame(read_bag(data_dir / "palpation" / name))
        for name in PALPATION_LOGS
    }


@pytest.fixture(scope="module")
def real_comparisons(real_logs):
    return {name: compare_models(data, sweep=True) for name, data in real_logs.items()}


@pytest.mark.realdata
@pytest.mark.parametrize("name", PALPATION_LOGS)
def test_hunt_crossley_beats_kelvin_voigt_on_real_logs(real_comparisons, name):
    c = real_comparisons[name]
    assert 0.0 <= c.lag_s <= 0.2
    assert c.hunt_crossley[1.35].rms_N < c.kelvin_voigt.rms_N
    assert c.hunt_crossley[1.35].relative < c.kelvin_voigt.relative
    # The paper's beta = 1.35 is close to each log's optimum.
    assert 1.2 <= c.best_beta <= 1.5
    assert c.hunt_crossley[1.35].kappa > 0 and c.hunt_crossley[1.35].lam > 0


@pytest.mark.realdata
def test_table_i_ordering_on_soft_1hz(real_comparisons):
    c = real_comparisons["test_soft_1hz"]
    hc = c.hunt_crossley
    assert (
        hc[1.35].relative
        < hc[1.5].relative
        < hc[1.1].relative
        < c.kelvin_voigt.relative
    )


def test_exponential_fit_is_robust_to_one_outlier():
    t = np.linspace(0.5, 30.0, 40)
    r = 0.1 * np.exp(-t / 4.0) + 0.02
    r[1] = 0.0  # One window that happened to generalise unusually well.
    fit = fit_exponential(t, r)
    assert fit.tau_s == pytest.approx(4.0, rel=0.1)
    assert fit.c == pytest.approx(0.02, rel=0.05)


def test_offline_figures(tmp_path):
    from matplotlib.figure import Figure

    from vic_drake.plots.offline import (
        plot_beta_sweep,
        plot_lag_profile,
        plot_palpation_summary,
        plot_residual_vs_time,
        plot_table_i,
    )

    data = synthetic_palpation(lag_s=0.02, noise_N=0.05, duration_s=8.0)
    comparison = compare_models(data)
    curve = residual_vs_palpation_time(shift(data, comparison.lag_s))
    figures = [
        plot_table_i({"synthetic": comparison, "again": comparison}),
        plot_beta_sweep(comparison.sweep),
        plot_residual_vs_time({"synthetic": curve}),
        plot_lag_profile(comparison.lag_profile),
        plot_palpation_summary(
            comparison, title="synthetic", save_path=tmp_path / "s.png"
        ),
    ]
    assert all(isinstance(f, Figure) for f in figures)
    # Bars: 4 models x 2 logs.
    assert len(figures[0].axes[0].patches) == 8
    assert (tmp_path / "s.png").stat().st_size > 10_000


def test_from_frame_drops_corrupt_rows():
    t = 0.002 * np.arange(6)
    df = pd.DataFrame(
        {
            "t_s": t[[0, 1, 3, 2, 3, 4, 5]],
            "surface_z_m": [-0.05] * 7,
            "z_target_m": [-0.06] * 7,
            "z_m": [-0.05, -0.051, -0.053, -0.052, -0.053, np.nan, -0.055],
            "vz_m_per_s": [0.0] * 7,
            "force_z_N": [-1.0, -2.0, -4.0, -3.0, -4.0, -5.0, -6.0],
        }
    )
    data = PalpationData.from_frame(df)
    np.testing.assert_allclose(data.t_s, t[[0, 1, 2, 3, 5]])
    np.testing.assert_allclose(data.force_N, [1.0, 2.0, 3.0, 4.0, 6.0])
    df["z_m"] = np.nan
    with pytest.raises(VicDrakeError, match="usable"):
        PalpationData.from_frame(df)


def test_samples_next_to_a_timestamp_gap_are_not_fitted():
    data = synthetic_palpation(duration_s=6.0, jitter_s=0.0)
    keep = (data.t_s < 2.0) | (data.t_s > 2.3)  # 0.3 s of dropped messages.
    gappy = data.select(keep)
    fit = fit_hunt_crossley(gappy, 1.35)
    before, after = gappy.t_s[gappy.t_s < 2.1][-1], gappy.t_s[gappy.t_s > 2.1][0]
    near = (gappy.t_s >= before - 0.05) & (gappy.t_s <= after + 0.05)
    assert abs(fit.n_samples - (gappy.n - near.sum())) <= 1  # Rounding at the edges.
    assert fit.n_samples < gappy.n - 45
    assert fit.kappa == pytest.approx(4000.0, rel=1e-3)
    assert fit.lam == pytest.approx(20000.0, rel=1e-2)


@pytest.mark.realdata
def test_real_logs_agree_on_the_soft_material(real_comparisons):
    """The three logs palpate the same soft material, so once the lag is
    removed their HC parameters should agree (an unremoved lag shows up as a
    wrong lambda: at lag 0 the 1 Hz log gives lambda ~ 1.6e3, 13x too low)."""
    fits = [c.hunt_crossley[1.35] for c in real_comparisons.values()]
    lams = np.array([f.lam for f in fits])
    assert np.all(np.abs(lams / lams.mean() - 1.0) < 0.25), lams
    # 1 and 2 Hz only: the 2.5 Hz log's logged surface sits ~1.5 mm above the
    # tissue (its force stays below 0.3 N over the first 3 mm of the fast
    # approach, half of which the ~50 ms lag explains), which lowers kappa.
    kappas = np.array([f.kappa for f in fits[:2]])
    assert abs(kappas[0] / kappas[1] - 1.0) < 0.1, kappas
    lags = np.array([c.lag_s for c in real_comparisons.values()])
    assert np.all((lags > 0.02) & (lags < 0.07)), lags


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


def test_surface_array_matches_scalar_surface():
    data = synthetic_palpation(noise_N=0.02, duration_s=4.0)
    as_array = PalpationData(
        data.t_s, data.z_m, data.force_N, np.full(data.n, data.surface_z_m)
    )
    a = fit_hunt_crossley(data, 1.35)
    b = fit_hunt_crossley(as_array, 1.35)
    assert b.kappa == pytest.approx(a.kappa, rel=1e-9)
    assert b.lam == pytest.approx(a.lam, rel=1e-6)
    # A rising surface (phantom lifted) changes eps_dot by s_dot.
    lift = 0.001 * data.t_s
    moving = PalpationData(
        data.t_s, data.z_m + lift, data.force_N, data.surface_z_m + lift
    )
    c = fit_hunt_crossley(moving, 1.35)
    assert c.kappa == pytest.approx(a.kappa, rel=1e-6)
    assert c.lam == pytest.approx(a.lam, rel=1e-3)
