"""PalpationData: reading a bag frame, validation, surfaces, timestamp gaps."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation import PalpationData, fit_hunt_crossley

from .synthetic import synthetic_palpation


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
