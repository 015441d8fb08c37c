"""A GP map of one field on a regular grid: fit, then predict.

:func:`gp_map` fits a GP (:func:`~vic_drake.estimation.gp_fit.fit_gp`) to
scattered values and evaluates its posterior mean and latent std on a grid
(:func:`~vic_drake.estimation.gp_predict.predict_grid`), timing both steps.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from vic_drake.estimation.gp_fit import (
    GpMapParams,
    _from_target,
    _to_target,
    fit_gp,
    length_scales,
)
from vic_drake.estimation.gp_predict import predict_grid


@dataclass(frozen=True)
class GpMap:
    """A GP map on a regular grid.

    Attributes:
        x_m, y_m: grid axes (nx,), (ny,).
        mean, std: (nx, ny) posterior mean and latent std, indexed [ix, iy].
        kernel: the fitted kernel, as text.
        length_scales_m: fitted (x, y) length scales.
        fit_s, predict_s: wall times, s.
    """

    x_m: np.ndarray
    y_m: np.ndarray
    mean: np.ndarray
    std: np.ndarray
    kernel: str
    length_scales_m: tuple[float, float]
    fit_s: float
    predict_s: float


def gp_map(
    x, y, values, xs, ys, params: GpMapParams | None = None, *, std_step: int = 1
) -> GpMap:
    """Fits a GP to (x, y, values) and evaluates it on the grid xs x ys.

    ``std_step``: see :func:`~vic_drake.estimation.gp_predict.predict_std_grid`.
    """
    params = params or GpMapParams()
    t0 = time.perf_counter()
    gp = fit_gp(x, y, _to_target(values, params), params)
    t1 = time.perf_counter()
    mean, std = _from_target(
        *predict_grid(gp, xs, ys, chunk_size=params.chunk_size, std_step=std_step),
        params,
    )
    t2 = time.perf_counter()
    return GpMap(
        x_m=np.asarray(xs, float),
        y_m=np.asarray(ys, float),
        mean=mean,
        std=std,
        kernel=str(gp.kernel_),
        length_scales_m=length_scales(gp),
        fit_s=t1 - t0,
        predict_s=t2 - t1,
    )
