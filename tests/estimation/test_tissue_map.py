"""The tissue map: surface fit and GP maps from fitted palpation points."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.analysis.map_compare import compare_with_phantom
from vic_drake.errors import VicDrakeError
from vic_drake.estimation.gp_fit import GpMapParams
from vic_drake.estimation.tissue_map import build_tissue_map
from vic_drake.tissue import SyntheticChestPhantom


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
