"""Identification from scan logs: phantom lift, force-loop gain."""

import numpy as np
import pandas as pd
import pytest

from tests.analysis.scans import make_scan
from vic_drake.analysis.identification import (
    estimate_force_loop_gain,
    estimate_phantom_lift,
    lift_table,
)
from vic_drake.errors import VicDrakeError
from vic_drake.tissue import hunt_crossley_force
from vic_drake.tissue.phantom import GridPhantom


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
    f = hunt_crossley_force(eps, np.gradient(eps, t), 4000, 40000, 1.35)
    df = make_scan(t, f, x_m=0.03 - 0.01 * t, y_m=-0.36, z_m=z)
    est = estimate_phantom_lift(df, phantom)
    assert list(est.columns) == ["t_s", "phantom_lift_m", "measured"]
    # Within 0.5 mm at the kinks of the trapezoid (the viscous rate is smoothed).
    np.testing.assert_allclose(est["phantom_lift_m"], lift, atol=5e-4)
    table = lift_table(est, dt_s=0.1)
    assert len(table) == 200 and table[70][1] == pytest.approx(0.015, abs=3e-4)


def test_force_loop_gain_recovers_a_known_integral_loop():
    """z' = G (K (z_d - z) + f_ref - f) with a Hunt-Crossley-like surface
    force and a bias: the estimate returns G and the bias."""

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
    short = estimate_force_loop_gain(
        df.iloc[:50], stiffness_z_N_per_m=k, force_ref_z_N=0.0
    )
    assert np.isnan(short["gain_m_per_s_per_N"])
    with pytest.raises(VicDrakeError, match="stiffness_z_N_per_m"):
        estimate_force_loop_gain(df)
