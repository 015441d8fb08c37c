"""Rib detection and the map-versus-phantom metrics."""

import numpy as np
import pandas as pd

from vic_drake.analysis.map_compare import compare_with_phantom
from vic_drake.analysis.ribs import find_ribs
from vic_drake.estimation.tissue_map import TissueMap, map_axis
from vic_drake.tissue import SyntheticChestPhantom


def test_find_ribs_finds_gaussian_bands():
    x = np.linspace(-0.1, 0.1, 2001)
    centres = [-0.06, -0.01, 0.045]
    profile = 3000 + sum(6000 * np.exp(-0.5 * ((x - c) / 0.006) ** 2) for c in centres)
    # Texture below the prominence rule (5 % of the median kappa).
    profile += 50 * np.sin(x / 0.03)
    np.testing.assert_allclose(find_ribs(x, profile).position_m, centres, atol=2e-4)
    assert find_ribs(x, np.full_like(x, 5.0)).position_m.size == 0


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
