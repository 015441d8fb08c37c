"""A simulated record against a real one: alignment, force lead, metrics."""

import numpy as np
import pytest

from tests.analysis.scans import make_scan
from vic_drake.analysis.real_comparison import (
    compare_contact_loss,
    compare_with_real,
    estimate_time_offset_s,
    lead_force,
)


def test_time_offset_recovers_a_known_shift():
    t = np.arange(0, 20, 0.002)
    rng = np.random.default_rng(0)
    signal = np.convolve(rng.normal(size=t.size), np.ones(200) / 200, "same")
    real = make_scan(t, 5 + signal)
    sim = make_scan(t - 0.13, 5 + signal)  # Sim runs 0.13 s early.
    assert estimate_time_offset_s(sim, real) == pytest.approx(0.13, abs=0.011)


def test_force_lead_undoes_a_sensor_lag():
    t = np.arange(0, 20, 0.002)
    f = 5 + np.sin(t)
    lagged = make_scan(t, np.interp(t - 0.056, t, f), z_m=0.1, tank_energy_J=0.5)
    real = make_scan(t, f, z_m=0.1, tank_energy_J=0.5)
    led = lead_force(lagged, 0.056)
    np.testing.assert_allclose(-led["force_sensor_z_N"][:-100], f[:-100], atol=1e-9)
    out = compare_with_real(lagged, real, align=False, force_lead_s=0.056)
    assert out["force_rmse_N"] < 1e-6


def test_compare_identical_records_is_perfect():
    t = np.arange(0, 10, 0.002)
    f = np.where(t < 1, 0.0, 7 + np.sin(t))
    k = 300 + 100 * np.sin(0.5 * t)
    df = make_scan(
        t, f, z_m=0.1 + 0.001 * np.sin(t), stiffness_z_N_per_m=k, tank_energy_J=0.5
    )
    out = compare_with_real(df, df)
    assert out["force_rmse_N"] == pytest.approx(0.0, abs=1e-12)
    assert out["z_rmse_mm"] == pytest.approx(0.0, abs=1e-12)
    assert out["kz_corr"] == pytest.approx(1.0)
    assert out["time_offset_s"] == 0.0


def test_contact_loss_comparison_counts_totals_and_overlap():
    t = np.arange(0, 10, 0.002)
    real_f = np.where((t > 3) & (t < 4), 0.0, 6.0)
    sim_f = np.where((t > 3.5) & (t < 4.2), 0.0, 6.0)
    out = compare_contact_loss(make_scan(t, sim_f), make_scan(t, real_f))
    assert out["contact_loss_total_real_s"] == pytest.approx(1.0, abs=0.005)
    assert out["contact_loss_total_sim_s"] == pytest.approx(0.7, abs=0.005)
    assert out["contact_loss_overlap_s"] == pytest.approx(0.5, abs=0.005)
    # No loss in either run: the figures are 0.0, not missing.
    none = compare_contact_loss(
        make_scan(t, np.full_like(t, 6.0)), make_scan(t, np.full_like(t, 6.0))
    )
    assert none["contact_loss_total_sim_s"] == 0.0
    assert none["contact_loss_total_real_s"] == 0.0
    assert none["contact_loss_overlap_s"] == 0.0
    assert none["contact_loss_real_s"] == []
