"""GRIDFIT-like regularised surface fit."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.surface import (
    bilinear_matrix,
    grid_axis,
    gridfit,
)


def dome(x, y):
    return (
        0.1 - 0.5 * (x + 0.06) ** 2 - 1.0 * (y + 0.36) ** 2 + 0.002 * np.sin(x / 0.03)
    )


@pytest.fixture(scope="module")
def samples():
    x, y = np.meshgrid(
        np.arange(-0.16, 0.0401, 0.01), np.arange(-0.41, -0.3099, 0.01), indexing="ij"
    )
    return x.ravel(), y.ravel()


def test_bilinear_matrix_is_exact_for_bilinear_functions():
    xn, yn = grid_axis(0.0, 1.0, 0.25), grid_axis(0.0, 2.0, 0.5)
    rng = np.random.default_rng(0)
    x, y = rng.uniform(0, 1, 50), rng.uniform(0, 2, 50)
    A = bilinear_matrix(x, y, xn, yn)
    np.testing.assert_allclose(A.sum(axis=1), 1.0)
    X, Y = np.meshgrid(xn, yn, indexing="ij")

    def f(x, y):
        return 1 + 2 * x - 3 * y + 0.5 * x * y

    np.testing.assert_allclose(A @ f(X, Y).ravel(), f(x, y), atol=1e-12)
    with pytest.raises(VicDrakeError, match="inside the node grid"):
        bilinear_matrix([1.5], [0.5], xn, yn)


def test_gridfit_reproduces_a_smooth_surface(samples):
    x, y = samples
    xn, yn = grid_axis(-0.16, 0.04, 0.005), grid_axis(-0.41, -0.31, 0.005)
    fit = gridfit(x, y, dome(x, y), x_nodes=xn, y_nodes=yn)
    gx, gy = np.linspace(-0.16, 0.04, 201), np.linspace(-0.41, -0.31, 101)
    est = fit.on_grid(gx, gy)
    truth = dome(*np.meshgrid(gx, gy, indexing="ij"))
    assert np.sqrt(np.mean((est - truth) ** 2)) < 2e-5  # 0.02 mm from 1 cm samples
    np.testing.assert_allclose(fit(x, y), dome(x, y), atol=1e-4)


def test_gcv_smooths_noisy_data_and_not_clean_data(samples):
    x, y = samples
    xn, yn = grid_axis(-0.16, 0.04, 0.005), grid_axis(-0.41, -0.31, 0.005)
    rng = np.random.default_rng(1)
    noise = 5e-4
    noisy = dome(x, y) + noise * rng.standard_normal(x.size)
    clean_fit = gridfit(x, y, dome(x, y), x_nodes=xn, y_nodes=yn)
    noisy_fit = gridfit(x, y, noisy, x_nodes=xn, y_nodes=yn)
    # GCV must pick far more smoothing for the noisy data, and the result must
    # beat both extremes of the candidate grid against the truth.
    assert noisy_fit.smoothness > 100 * clean_fit.smoothness
    assert noisy_fit.effective_dof < 0.5 * x.size
    truth = dome(x, y)
    err = np.sqrt(np.mean((noisy_fit(x, y) - truth) ** 2))
    assert err < 0.6 * noise
    for s in (noisy_fit.smoothness_grid[0], noisy_fit.smoothness_grid[-1]):
        other = gridfit(x, y, noisy, x_nodes=xn, y_nodes=yn, smoothness=s)
        assert err <= np.sqrt(np.mean((other(x, y) - truth) ** 2))
    assert np.argmin(noisy_fit.gcv) not in (0, noisy_fit.gcv.size - 1)


def test_gridfit_rejects_bad_input(samples):
    x, y = samples
    xn, yn = grid_axis(-0.16, 0.04, 0.01), grid_axis(-0.41, -0.31, 0.01)
    with pytest.raises(VicDrakeError, match="finite"):
        gridfit(x, y, np.full(x.size, np.nan), x_nodes=xn, y_nodes=yn)
    with pytest.raises(VicDrakeError, match="smoothness"):
        gridfit(x, y, dome(x, y), x_nodes=xn, y_nodes=yn, smoothness=-1.0)
    with pytest.raises(VicDrakeError, match="at least 4"):
        gridfit(x[:3], y[:3], dome(x[:3], y[:3]), x_nodes=xn, y_nodes=yn)
    with pytest.raises(VicDrakeError, match="lo < hi"):
        grid_axis(1.0, 0.0, 0.1)
