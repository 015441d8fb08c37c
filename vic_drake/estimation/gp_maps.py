"""Gaussian-process maps of kappa and lambda over the palpated region.

The names of the map pipeline, kept importable from this module. Each lives
in the module of its concept:

- :mod:`vic_drake.estimation.gp_fit`: GP settings, kernel and fit.
- :mod:`vic_drake.estimation.gp_predict`: prediction on points and grids.
- :mod:`vic_drake.estimation.gp_grid`: one field's GP map on a grid.
- :mod:`vic_drake.estimation.tissue_map`: surface and kappa/lambda maps.
"""

from vic_drake.estimation.gp_fit import (
    KERNELS,
    GpMapParams,
    fit_gp,
    length_scales,
    make_kernel,
    nearest_neighbour_spacing,
)
from vic_drake.estimation.gp_grid import GpMap, gp_map
from vic_drake.estimation.gp_predict import (
    predict_grid,
    predict_mean_grid,
    predict_points,
    predict_std_grid,
)
from vic_drake.estimation.tissue_map import TissueMap, build_tissue_map, map_axis

__all__ = [
    "KERNELS",
    "GpMap",
    "GpMapParams",
    "TissueMap",
    "build_tissue_map",
    "fit_gp",
    "gp_map",
    "length_scales",
    "make_kernel",
    "map_axis",
    "nearest_neighbour_spacing",
    "predict_grid",
    "predict_mean_grid",
    "predict_points",
    "predict_std_grid",
]
