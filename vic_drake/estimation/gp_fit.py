"""Gaussian-process regression of one tissue parameter over (x, y).

The paper interpolates the per-point Hunt-Crossley parameters with two
Gaussian-process regressions (MATLAB ``fitrgp``), one for elasticity and one
for viscosity, input the indenter position. Here: scikit-learn's
:class:`GaussianProcessRegressor` with kernel

    ConstantKernel * RBF(anisotropic length scales along x and y)
        + WhiteKernel(measurement noise)

(or a Matern kernel), ``normalize_y=True``, hyperparameters by maximum
marginal likelihood with restarts (:func:`fit_gp`). The maps are the
posterior mean and standard deviation of the LATENT field (the white-noise
term is left out of the predictive std: it is the scatter of a single fit,
not the uncertainty of the map); ``_latent_kernel`` gives that part of the
fitted kernel.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, Matern, WhiteKernel
from threadpoolctl import threadpool_limits

from vic_drake.errors import VicDrakeError

KERNELS = ("rbf", "matern")


@dataclass(frozen=True)
class GpMapParams:
    """Gaussian-process map settings (lengths in m).

    Attributes:
        kernel: "rbf" (squared exponential) or "matern".
        matern_nu: smoothness of the Matern kernel.
        length_scale_m: initial length scale (x and y).
        length_scale_bounds_m: bounds of the length scales.
        noise_level_bounds: bounds of the WhiteKernel variance (in units of
            the normalised target, i.e. a fraction of its variance).
        min_length_scale_spacing: the lower length-scale bound is raised to
            this fraction of the median nearest-neighbour spacing of the data:
            a field varying faster than half the sampling spacing is not
            identifiable from the samples, and without this bound a few
            points across a rib let the fit collapse to a length scale of
            1 mm (a map that is the mean everywhere between the points).
        n_restarts: optimiser restarts from random hyperparameters (the
            marginal likelihood of lambda on the synthetic chest has local
            optima; docs/decisions.md, "GP restarts").
        log_target: model log(value) instead of the value (the paper models
            the value). The map is then exp(mean) (the log-normal median)
            and its std exp(mean) * std_log (first order). Positive by
            construction; it helps on sharp ribs and hurts on a map that is
            itself a GP in linear space (docs/decisions.md, "GP target in
            log space").
        chunk_size: grid points predicted per chunk.
        seed: seed of the restarts.
    """

    kernel: str = "rbf"
    matern_nu: float = 2.5
    length_scale_m: float = 0.02
    length_scale_bounds_m: tuple[float, float] = (1e-3, 0.5)
    noise_level_bounds: tuple[float, float] = (1e-6, 1.0)
    min_length_scale_spacing: float = 0.5
    n_restarts: int = 8
    log_target: bool = False
    chunk_size: int = 50_000
    seed: int = 0

    def __post_init__(self):
        if self.kernel not in KERNELS:
            raise VicDrakeError(
                f"GpMapParams.kernel must be one of {KERNELS}, got {self.kernel!r}"
            )
        lo, hi = self.length_scale_bounds_m
        if not (0 < lo < hi and lo <= self.length_scale_m <= hi):
            raise VicDrakeError(
                "GpMapParams.length_scale_bounds_m must be 0 < lo < hi around length_scale_m, "
                f"got {self.length_scale_bounds_m!r} and {self.length_scale_m!r}"
            )
        lo, hi = self.noise_level_bounds
        if not 0 < lo < hi:
            raise VicDrakeError(
                f"GpMapParams.noise_level_bounds must be 0 < lo < hi, got {self.noise_level_bounds!r}"
            )
        if not (
            np.isfinite(self.min_length_scale_spacing)
            and self.min_length_scale_spacing >= 0
        ):
            raise VicDrakeError(
                "GpMapParams.min_length_scale_spacing must be >= 0, got "
                f"{self.min_length_scale_spacing!r}"
            )
        if int(self.n_restarts) != self.n_restarts or self.n_restarts < 0:
            raise VicDrakeError(
                f"GpMapParams.n_restarts must be an integer >= 0, got {self.n_restarts!r}"
            )
        if int(self.chunk_size) != self.chunk_size or self.chunk_size < 1:
            raise VicDrakeError(
                f"GpMapParams.chunk_size must be an integer >= 1, got {self.chunk_size!r}"
            )


def nearest_neighbour_spacing(x, y) -> float:
    """Median distance from each point to its nearest neighbour, m."""
    pts = np.column_stack([np.asarray(x, float), np.asarray(y, float)])
    if len(pts) < 2:
        return 0.0
    d, _ = cKDTree(pts).query(pts, k=2)
    return float(np.median(d[:, 1]))


def make_kernel(params: GpMapParams, *, min_length_scale_m: float = 0.0):
    """ConstantKernel * (RBF | Matern)(anisotropic) + WhiteKernel.

    ``min_length_scale_m`` raises the lower length-scale bound (see
    GpMapParams.min_length_scale_spacing).
    """
    lo, hi = params.length_scale_bounds_m
    lo = min(max(lo, min_length_scale_m), 0.5 * hi)
    start = float(np.clip(params.length_scale_m, lo, hi))
    ls = [start, start]
    if params.kernel == "rbf":
        shape = RBF(length_scale=ls, length_scale_bounds=(lo, hi))
    else:
        shape = Matern(
            length_scale=ls, length_scale_bounds=(lo, hi), nu=params.matern_nu
        )
    return ConstantKernel(1.0, (1e-3, 1e3)) * shape + WhiteKernel(
        1e-2, noise_level_bounds=params.noise_level_bounds
    )


def fit_gp(x, y, values, params: GpMapParams | None = None) -> GaussianProcessRegressor:
    """Fits a GP to scattered values at (x, y) (hyperparameters learned).

    Raises:
        VicDrakeError: mismatched sizes, non-finite data, fewer than 3 points.
    """
    params = params or GpMapParams()
    x, y, values = (np.asarray(a, float).ravel() for a in (x, y, values))
    if not (x.size == y.size == values.size):
        raise VicDrakeError(
            f"fit_gp: x, y, values sizes differ ({x.size}, {y.size}, {values.size})"
        )
    if not np.all(np.isfinite(x) & np.isfinite(y) & np.isfinite(values)):
        raise VicDrakeError("fit_gp: x, y and values must be finite")
    if x.size < 3:
        raise VicDrakeError(f"fit_gp needs at least 3 points, got {x.size}")
    gp = GaussianProcessRegressor(
        kernel=make_kernel(
            params,
            min_length_scale_m=params.min_length_scale_spacing
            * nearest_neighbour_spacing(x, y),
        ),
        normalize_y=True,
        n_restarts_optimizer=int(params.n_restarts),
        random_state=int(params.seed),
    )
    # A few hundred points: one BLAS thread is as fast, and it avoids thread
    # oversubscription (docs/decisions.md, "One BLAS thread for GP fits").
    with warnings.catch_warnings(), threadpool_limits(limits=1, user_api="blas"):
        # A hyperparameter at its bound is reported in the fitted kernel.
        warnings.simplefilter("ignore", ConvergenceWarning)
        gp.fit(np.column_stack([x, y]), values)
    return gp


def _latent_kernel(gp: GaussianProcessRegressor):
    """The fitted kernel without its WhiteKernel term."""
    kernel = gp.kernel_
    if hasattr(kernel, "k2") and isinstance(kernel.k2, WhiteKernel):
        return kernel.k1
    return kernel


def length_scales(gp: GaussianProcessRegressor) -> tuple[float, float]:
    """Fitted (x, y) length scales of the kernel's RBF/Matern factor, m."""
    k = _latent_kernel(gp)
    shape = k.k2 if hasattr(k, "k2") else k
    ls = np.broadcast_to(np.asarray(shape.length_scale, float), (2,))
    return float(ls[0]), float(ls[1])


def _to_target(values, params: GpMapParams) -> np.ndarray:
    values = np.asarray(values, float)
    if not params.log_target:
        return values
    if np.any(~(values > 0)):
        raise VicDrakeError("log_target needs positive values (a fit gave <= 0)")
    return np.log(values)


def _from_target(mean, std, params: GpMapParams):
    if not params.log_target:
        return mean, std
    value = np.exp(mean)
    return value, value * std
