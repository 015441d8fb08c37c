"""GP prediction on grids against scikit-learn (fixtures in conftest.py)."""

import numpy as np

from vic_drake.estimation.gp_predict import (
    predict_mean_grid,
    predict_points,
    predict_std_grid,
)
from vic_drake.estimation.tissue_map import map_axis


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
