"""GP settings, kernels and the fit (fixtures in conftest.py)."""

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.gp_fit import GpMapParams, fit_gp
from vic_drake.estimation.gp_grid import gp_map
from vic_drake.estimation.tissue_map import map_axis


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
