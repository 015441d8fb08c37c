"""Gaussian-process maps, rib detection and the map-versus-phantom metrics."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.gp_maps import (
    GpMapParams,
    TissueMap,
    build_tissue_map,
    compare_with_phantom,
    find_ribs,
    fit_gp,
    gp_map,
    map_axis,
    predict_mean_grid,
    predict_points,
    predict_std_grid,
)
from vic_drake.tissue import SyntheticChestPhantom


def field(x, y):
    return 4000.0 + 1500.0 * np.sin(x / 0.02) * np.cos(y / 0.04)


@pytest.fixture(scope="module")
def samples():
    x, y = np.meshgrid(
        np.arange(0.0, 0.1001, 0.01), np.arange(0.0, 0.0801, 0.01), indexing="ij"
    )
    x, y = x.ravel(), y.ravel()
    rng = np.random.default_rng(0)
    return x, y, field(x, y) * (1 + 0.01 * rng.standard_normal(x.size))


@pytest.fixture(scope="module")
def gp(samples):
    return fit_gp(*samples)


def test_gp_map_recovers_a_smooth_field(samples):
    xs, ys = map_axis(0.0, 0.1, 0.002), map_axis(0.0, 0.08, 0.002)
    m = gp_map(*samples, xs, ys)
    truth = field(*np.meshgrid(xs, ys, indexing="ij"))
    rel = np.sqrt(np.mean(((m.mean - truth) / truth) ** 2))
    assert rel < 0.02
    assert m.mean.shape == m.std.shape == (xs.size, ys.size)
    # The std is the uncertainty of the field: small near data, within 1 %.
    assert np.median(m.std) < 0.02 * 4000.0


def test_grid_prediction_matches_sklearn(gp):
    xs, ys = map_axis(0.0, 0.1, 0.005), map_axis(0.0, 0.08, 0.005)
    X = np.column_stack([np.repeat(xs, ys.size), np.tile(ys, xs.size)])
    mean = predict_mean_grid(gp, xs, ys)
    np.testing.assert_allclose(mean.ravel(), gp.predict(X), rtol=1e-9)
    m, s = predict_points(gp, X)
    np.testing.assert_allclose(m, gp.predict(X), rtol=1e-9)
    # Latent std = sklearn's std without the white-noise variance.
    _, s_noisy = gp.predict(X, return_std=True)
    noise = gp.kernel_.k2.noise_level * np.atleast_1d(gp._y_train_std)[0] ** 2
    np.testing.assert_allclose(
        s,
        np.sqrt(np.clip(s_noisy**2 - noise, 0, None)),
        rtol=1e-6,
        atol=1e-6 * np.max(s),
    )


def test_std_on_a_subgrid_is_close_to_exact(gp):
    xs, ys = map_axis(0.0, 0.1, 0.0005), map_axis(0.0, 0.08, 0.0005)
    exact = predict_std_grid(gp, xs, ys, step=1)
    coarse = predict_std_grid(gp, xs, ys, step=4)
    assert np.max(np.abs(coarse - exact)) < 0.01 * np.max(exact)


def test_matern_kernel_and_bad_params(samples):
    m = gp_map(
        *samples,
        map_axis(0, 0.1, 0.01),
        map_axis(0, 0.08, 0.01),
        GpMapParams(kernel="matern", n_restarts=0),
    )
    assert "Matern" in m.kernel
    with pytest.raises(VicDrakeError, match="kernel"):
        GpMapParams(kernel="cubic")
    with pytest.raises(VicDrakeError, match="at least 3"):
        fit_gp([0.0, 1.0], [0.0, 1.0], [1.0, 2.0])


def test_find_ribs_finds_gaussian_bands():
    x = np.linspace(-0.1, 0.1, 2001)
    centres = [-0.06, -0.01, 0.045]
    profile = 3000 + sum(6000 * np.exp(-0.5 * ((x - c) / 0.006) ** 2) for c in centres)
    profile += 200 * np.sin(x / 0.03)  # texture below the prominence threshold
    np.testing.assert_allclose(find_ribs(x, profile), centres, atol=2e-4)
    assert find_ribs(x, np.full_like(x, 5.0)).size == 0


def test_perfect_map_scores_zero_and_finds_the_true_ribs():
    phantom = SyntheticChestPhantom()
    region = (-0.16, 0.04, -0.38, -0.34)
    xs, ys = (
        map_axis(region[0], region[1], 0.001),
        map_axis(region[2], region[3], 0.001),
    )
    truth = phantom.sample(*np.meshgrid(xs, ys, indexing="ij"))
    points = pd.DataFrame({"x_m": [0.0], "y_m": [0.0], "ok": [True]})
    tmap = TissueMap(
        xs,
        ys,
        truth.surface_z_m,
        truth.kappa,
        truth.lam,
        0 * truth.kappa,
        0 * truth.lam,
        1.35,
        points,
        None,
        "",
        "",
        {},
    )
    c = compare_with_phantom(tmap, phantom)
    assert (
        c.kappa_rmse_pct == 0.0
        and c.lambda_rmse_pct == 0.0
        and c.surface_rmse_mm == 0.0
    )
    expected = phantom.rib_centres_x(c.y_line_m)
    expected = expected[(expected >= xs[0] + 0.01) & (expected <= xs[-1] - 0.01)]
    np.testing.assert_allclose(c.ribs_true, expected)
    np.testing.assert_allclose(c.ribs_found, expected, atol=1.5e-3)


def test_build_tissue_map_from_synthetic_points():
    phantom = SyntheticChestPhantom()
    region = (-0.10, 0.0, -0.40, -0.33)
    x, y = np.meshgrid(
        np.arange(region[0], region[1] + 1e-9, 0.01),
        np.arange(region[2], region[3] + 1e-9, 0.01),
        indexing="ij",
    )
    x, y = x.ravel(), y.ravel()
    truth = phantom.sample(x, y)
    points = pd.DataFrame(
        {
            "x_m": x,
            "y_m": y,
            "surface_z_m": truth.surface_z_m,
            "kappa_N_per_m_beta": truth.kappa,
            "lambda_N_s_per_m_beta1": truth.lam,
            "ok": np.ones(x.size, bool),
        }
    )
    tmap = build_tissue_map(
        points, region, beta=1.35, resolution_m=0.002, gp=GpMapParams(n_restarts=1)
    )
    assert tmap.kappa.shape == (51, 36)
    c = compare_with_phantom(tmap, phantom)
    assert c.surface_rmse_mm < 0.1
    assert c.kappa_rmse_pct < 15.0  # ribs 6 mm wide sampled every 10 mm
    assert len(c.ribs_found) == len(c.ribs_true)
    assert max(c.rib_errors_m) < 2e-3
    with pytest.raises(VicDrakeError, match="at least 4"):
        build_tissue_map(points.iloc[:3], region, beta=1.35)


def test_log_target_map_is_positive_and_accurate(samples):
    xs, ys = map_axis(0.0, 0.1, 0.005), map_axis(0.0, 0.08, 0.005)
    m = gp_map(*samples, xs, ys, GpMapParams(log_target=True, n_restarts=1))
    truth = field(*np.meshgrid(xs, ys, indexing="ij"))
    assert np.all(m.mean > 0) and np.all(m.std >= 0)
    assert np.sqrt(np.mean(((m.mean - truth) / truth) ** 2)) < 0.03
    x, y, v = samples
    with pytest.raises(VicDrakeError, match="positive"):
        gp_map(x, y, v - 10_000.0, xs, ys, GpMapParams(log_target=True))
