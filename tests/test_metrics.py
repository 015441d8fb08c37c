"""Scan metrics on synthetic records with known answers, and on the real logs."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.metrics import (
    CANONICAL_COLUMNS,
    compare_contact_loss,
    compare_with_real,
    contact_loss_intervals,
    estimate_phantom_lift,
    estimate_time_offset_s,
    force_range_N,
    force_rmse_N,
    lead_force,
    lift_table,
    lifted_off,
    peak_force_N,
    penetration_stats,
    real_to_canonical,
    scan_window,
    tank_min_J,
)
from vic_drake.tissue.phantom import GridPhantom, SyntheticChestPhantom


def make_scan(t, force_pressing, **columns) -> pd.DataFrame:
    df = pd.DataFrame({c: np.full(len(t), np.nan) for c in CANONICAL_COLUMNS})
    df["t_s"] = t
    df["force_sensor_z_N"] = -np.asarray(force_pressing, float)
    for key, value in columns.items():
        df[key] = value
    return df


def test_force_rmse_and_range_against_hand_values():
    t = np.arange(0, 10, 0.002)
    f = np.where(t < 1, 0.0, 7.0 + np.sin(2 * np.pi * t))  # Contact from t = 1.
    df = make_scan(t, f, force_ref_z_N=-7.0)
    window = scan_window(df, settle_s=1.0)
    assert t[window][0] == pytest.approx(2.0, abs=0.003)
    # RMS of a unit sine over whole periods is 1/sqrt(2).
    assert force_rmse_N(df) == pytest.approx(1 / np.sqrt(2), rel=2e-3)
    lo, hi = force_range_N(df)
    assert lo == pytest.approx(6.0, abs=1e-4) and hi == pytest.approx(8.0, abs=1e-4)
    assert peak_force_N(df) == pytest.approx(8.0, abs=1e-4)


def test_contact_loss_intervals_ignore_short_dips_and_free_motion():
    t = np.arange(0, 10, 0.002)
    f = np.full(t.size, 5.0)
    f[t < 1] = 0.0  # Approach: not a loss.
    f[(t > 3) & (t < 3.02)] = 0.0  # 20 ms dip: noise, ignored.
    f[(t >= 5) & (t < 6)] = 0.1  # A real loss of 1 s.
    f[t > 9] = 0.0  # Lift-off: not a loss.
    df = make_scan(t, f)
    (loss,) = contact_loss_intervals(df)
    assert loss[0] == pytest.approx(5.0, abs=0.003) and loss[1] == pytest.approx(
        6.0, abs=0.003
    )
    assert lifted_off(df)
    cmp = compare_contact_loss(df, df)
    assert cmp["contact_loss_overlap_s"] == pytest.approx(1.0, abs=0.005)


def test_tank_min_and_missing_columns():
    t = np.arange(0, 1, 0.01)
    df = make_scan(t, np.ones_like(t), tank_energy_J=0.5 - 0.1 * t)
    assert tank_min_J(df) == pytest.approx(0.401)
    with pytest.raises(VicDrakeError, match="lacks columns"):
        force_rmse_N(pd.DataFrame({"t_s": t}))


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


def test_penetration_stats_split_ribs_from_soft_tissue():
    phantom = SyntheticChestPhantom()
    t = np.arange(0, 20, 0.01)
    x = 0.036 - 0.01 * t
    y = np.full_like(t, -0.36)
    kappa = phantom.kappa(x, y)
    pen = np.where(kappa > 7000, 0.003, 0.008)
    df = make_scan(t, np.full_like(t, 7.0), x_m=x, y_m=y, penetration_m=pen)
    stats = penetration_stats(df, phantom)
    assert stats.rib_samples > 0 and stats.soft_samples > stats.rib_samples
    assert stats.rib_mean_m == pytest.approx(
        0.003
    ) and stats.soft_mean_m == pytest.approx(0.008)


def test_lift_estimate_recovers_a_lift_on_a_flat_phantom():
    """Forward-simulate the static HC law on a lifted flat phantom and invert it."""
    xs, ys = np.linspace(-0.2, 0.1, 31), np.linspace(-0.45, -0.28, 18)
    kappa = np.full((31, 18), 4000.0)
    phantom = GridPhantom(
        x_m=xs,
        y_m=ys,
        z_m=np.full((31, 18), 0.1),
        kappa=kappa,
        lam=kappa * 10,
        beta=1.35,
    )
    t = np.arange(0, 20, 0.002)
    lift = 0.015 * np.clip(np.minimum(t - 5, 9 - t), 0, 1)  # Trapezoid 5-10 s.
    z = 0.095 + 0.5 * lift  # The robot is pushed up by half the lift.
    eps = 0.1 + lift - z
    f = 4000 * eps**1.35
    df = make_scan(t, f, x_m=0.03 - 0.01 * t, y_m=-0.36, z_m=z)
    est = estimate_phantom_lift(df, phantom, smooth_s=0.05)
    np.testing.assert_allclose(est["phantom_lift_m"], lift, atol=2e-4)
    table = lift_table(est, dt_s=0.1)
    assert len(table) == 200 and table[60][1] == pytest.approx(0.015, abs=3e-4)


@pytest.mark.realdata
def test_real_logs_convert_to_the_canonical_layout(data_dir):
    from vic_drake.realdata import read_bag

    real = real_to_canonical(read_bag(data_dir / "experiments" / "test_tracking5"))
    assert tuple(real.columns) == CANONICAL_COLUMNS
    # VS-CF at a 7 N reference: the real controller tracked it to within ~1 N.
    assert force_rmse_N(real) < 1.5
    assert tank_min_J(real) == pytest.approx(0.9708, abs=1e-3)
    cs = real_to_canonical(
        read_bag(data_dir / "experiments" / "test_compliance_control400")
    )
    assert np.isnan(cs["x_d_m"]).all() and (cs["force_sensor_z_N"] < 0).all()
    with pytest.raises(VicDrakeError, match="layout"):
        real_to_canonical(read_bag(data_dir / "palpation" / "test_soft_1hz"))


def test_force_loop_gain_recovers_a_known_integral_loop():
    """z' = G (K (z_d - z) + f_ref - f) with a Hunt-Crossley-like surface
    force and a bias: the estimate returns G and the bias."""
    from vic_drake.metrics import estimate_force_loop_gain

    dt, g, k, bias = 0.002, 2.0e-3, 400.0, 0.3
    t = np.arange(0.0, 20.0, dt)
    surface = 0.1 + 0.01 * np.sin(2 * np.pi * 0.1 * t)
    z_d = np.full_like(t, 0.085)
    z = np.empty_like(t)
    z[0] = 0.095
    force = np.empty_like(t)  # Sensor convention: negative = pressing.
    for i in range(len(t)):
        force[i] = -1500.0 * max(surface[i] - z[i], 0.0) ** 1.2 * 10 - bias
        if i + 1 < len(t):
            z[i + 1] = z[i] + dt * g * (k * (z_d[i] - z[i]) - (force[i] + bias))
    df = pd.DataFrame({"t_s": t, "z_m": z, "z_d_m": z_d, "force_sensor_z_N": force})
    est = estimate_force_loop_gain(df, stiffness_z_N_per_m=k, force_ref_z_N=0.0)
    assert est["gain_m_per_s_per_N"] == pytest.approx(g, rel=0.02)
    assert est["offset_N"] == pytest.approx(bias, abs=0.02)
    assert est["r2"] > 0.99
    short = estimate_force_loop_gain(df.iloc[:50], stiffness_z_N_per_m=k, force_ref_z_N=0.0)
    assert np.isnan(short["gain_m_per_s_per_N"])
    with pytest.raises(VicDrakeError, match="stiffness_z_N_per_m"):
        estimate_force_loop_gain(df)
