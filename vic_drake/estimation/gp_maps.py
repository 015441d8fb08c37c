"""Gaussian-process maps of kappa and lambda over the palpated region.

The paper interpolates the per-point Hunt-Crossley parameters with two
Gaussian-process regressions (MATLAB ``fitrgp``), one for elasticity and one
for viscosity, input the indenter position, and evaluates them every 0.1 mm
(Fig. 4). Here: scikit-learn's :class:`GaussianProcessRegressor` with kernel

    ConstantKernel * RBF(anisotropic length scales along x and y)
        + WhiteKernel(measurement noise)

(or a Matern kernel), ``normalize_y=True``, hyperparameters by maximum
marginal likelihood with restarts. The maps are the posterior mean and
standard deviation of the LATENT field (the white-noise term is left out of
the predictive std: it is the scatter of a single fit, not the uncertainty
of the map).

Prediction on a fine grid (2001 x 1001 = 2 M points at 0.1 mm over 20 x
10 cm): with the RBF kernel the mean factorises along x and y and is one
matrix product; the std (n_train^2 work per point) is computed in chunks of
``chunk_size`` points from the fitted Cholesky factor, optionally on a
coarser sub-grid and splined (see :func:`predict_std_grid`).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import RectBivariateSpline
from scipy.linalg import solve_triangular
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
            optima: 3 restarts gave a 22 % map error, 8 gave 19 %).
        log_target: model log(value) instead of the value (the paper models
            the value). The map is then exp(mean) (the log-normal median)
            and its std exp(mean) * std_log (first order). Positive by
            construction; on the synthetic chest (sharp ribs) it cut the
            lambda map error from 19 % to 6 %, on the measured map (itself
            a GP in linear space) it raised it from 5.7 % to 7.5 %.
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
    from scipy.spatial import cKDTree

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
    # A few hundred points: one BLAS thread is as fast, and it avoids the
    # thread oversubscription that slowed fits 10-20x on a loaded 2-core box.
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


def predict_points(gp: GaussianProcessRegressor, X: np.ndarray):
    """Latent posterior mean and std at points X (m, 2), in the target's units."""
    k = _latent_kernel(gp)
    K_trans = k(X, gp.X_train_)
    mean = K_trans @ gp.alpha_
    v = solve_triangular(gp.L_, K_trans.T, lower=True, check_finite=False)
    var = k.diag(X) - np.einsum("ij,ij->j", v, v)
    std = np.sqrt(np.clip(var, 0.0, None))
    y_std = np.atleast_1d(gp._y_train_std)[0]
    y_mean = np.atleast_1d(gp._y_train_mean)[0]
    return mean * y_std + y_mean, std * y_std


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


def _separable_rbf(gp: GaussianProcessRegressor):
    """(c, lx, ly) if the latent kernel is ConstantKernel * anisotropic RBF, else None."""
    k = _latent_kernel(gp)
    if not (
        hasattr(k, "k1")
        and isinstance(k.k1, ConstantKernel)
        and isinstance(k.k2, RBF)
        and not isinstance(k.k2, Matern)
    ):
        return None
    ls = np.broadcast_to(np.asarray(k.k2.length_scale, float), (2,))
    return float(k.k1.constant_value), float(ls[0]), float(ls[1])


def predict_mean_grid(
    gp: GaussianProcessRegressor, xs, ys, *, chunk_size: int = 50_000
):
    """Posterior mean on the grid xs x ys, (nx, ny).

    With an RBF kernel the kernel factorises along x and y, so the mean is
    one matrix product ``(E_x diag(alpha)) E_y^T`` (exact, any grid size);
    other kernels are evaluated in chunks of whole x-rows.
    """
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    y_std = np.atleast_1d(gp._y_train_std)[0]
    y_mean = np.atleast_1d(gp._y_train_mean)[0]
    alpha = np.asarray(gp.alpha_).ravel()
    sep = _separable_rbf(gp)
    if sep is not None:
        c, lx, ly = sep
        Ex = np.exp(-0.5 * ((xs[:, None] - gp.X_train_[None, :, 0]) / lx) ** 2)
        Ey = np.exp(-0.5 * ((ys[:, None] - gp.X_train_[None, :, 1]) / ly) ** 2)
        return (c * (Ex * alpha) @ Ey.T) * y_std + y_mean
    k = _latent_kernel(gp)
    nx, ny = xs.size, ys.size
    mean = np.empty((nx, ny))
    rows = max(1, chunk_size // ny)
    for i0 in range(0, nx, rows):
        i1 = min(nx, i0 + rows)
        X = np.column_stack([np.repeat(xs[i0:i1], ny), np.tile(ys, i1 - i0)])
        mean[i0:i1] = (k(X, gp.X_train_) @ alpha).reshape(i1 - i0, ny)
    return mean * y_std + y_mean


def _subgrid(axis: np.ndarray, step: int) -> np.ndarray:
    idx = np.arange(0, axis.size, step)
    if idx[-1] != axis.size - 1:
        idx = np.append(idx, axis.size - 1)
    return axis[idx]


def predict_std_grid(
    gp: GaussianProcessRegressor, xs, ys, *, step: int = 1, chunk_size: int = 50_000
):
    """Latent posterior std on the grid xs x ys, (nx, ny).

    The std costs n_train^2 per point; with ``step`` > 1 it is computed
    exactly on every ``step``-th grid line (and the last) and interpolated
    by a bicubic spline in between. The std varies over the kernel's length
    scales (millimetres to centimetres), so a 1 mm sub-grid under a 0.1 mm
    map loses nothing visible.
    """
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    sx, sy = (_subgrid(xs, step), _subgrid(ys, step)) if step > 1 else (xs, ys)
    nx, ny = sx.size, sy.size
    std = np.empty((nx, ny))
    rows = max(1, chunk_size // ny)
    for i0 in range(0, nx, rows):
        i1 = min(nx, i0 + rows)
        X = np.column_stack([np.repeat(sx[i0:i1], ny), np.tile(sy, i1 - i0)])
        std[i0:i1] = predict_points(gp, X)[1].reshape(i1 - i0, ny)
    if step == 1 or (nx == xs.size and ny == ys.size):
        return std
    spline = RectBivariateSpline(sx, sy, std, kx=min(3, nx - 1), ky=min(3, ny - 1), s=0)
    return np.clip(spline(xs, ys, grid=True), 0.0, None)


def predict_grid(
    gp: GaussianProcessRegressor, xs, ys, *, chunk_size: int = 50_000, std_step: int = 1
):
    """Posterior mean and latent std on the grid xs x ys, (nx, ny) each."""
    mean = predict_mean_grid(gp, xs, ys, chunk_size=chunk_size)
    std = predict_std_grid(gp, xs, ys, step=std_step, chunk_size=chunk_size)
    return mean, std


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


def gp_map(
    x, y, values, xs, ys, params: GpMapParams | None = None, *, std_step: int = 1
) -> GpMap:
    """Fits a GP to (x, y, values) and evaluates it on the grid xs x ys.

    ``std_step``: see :func:`predict_std_grid`.
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


# ---------------------------------------------------------------------------
# The tissue map: surface (GRIDFIT) + GP kappa and lambda, and its checks.


@dataclass
class TissueMap:
    """Surface, kappa and lambda maps on a regular grid (the paper's Fig. 4-5).

    Arrays are indexed [ix, iy] like the measured ``phantom_map``.

    Attributes:
        x_m, y_m: grid axes, m (robot base frame).
        surface_z_m: tissue surface height (GRIDFIT of the contact points), m.
        kappa, lam: GP posterior means, N/m^beta and N s/m^(beta+1).
        kappa_std, lam_std: their latent posterior std.
        beta: Hunt-Crossley exponent.
        points: the per-point fits used (DataFrame of the campaign).
        surface_fit: the :class:`~vic_drake.estimation.surface.GridFit`.
        kappa_kernel, lam_kernel: fitted kernels, as text.
        timings_s: wall time per stage.
    """

    x_m: np.ndarray
    y_m: np.ndarray
    surface_z_m: np.ndarray
    kappa: np.ndarray
    lam: np.ndarray
    kappa_std: np.ndarray
    lam_std: np.ndarray
    beta: float
    points: object
    surface_fit: object
    kappa_kernel: str
    lam_kernel: str
    timings_s: dict

    @property
    def resolution_m(self) -> float:
        return float(self.x_m[1] - self.x_m[0]) if self.x_m.size > 1 else float("nan")

    def save_npz(self, path) -> None:
        """Writes x, y (axes, float64), surface, kappa, lambda, kappa_std,
        lambda_std ((nx, ny) float32, m and SI units), beta, and the
        palpation points (points_x, points_y, points_surface, points_kappa,
        points_lambda, float64)."""
        ok = self.points[self.points["ok"]]
        np.savez(
            path,
            x=self.x_m,
            y=self.y_m,
            surface=self.surface_z_m.astype(np.float32),
            kappa=self.kappa.astype(np.float32),
            **{"lambda": self.lam.astype(np.float32)},
            kappa_std=self.kappa_std.astype(np.float32),
            lambda_std=self.lam_std.astype(np.float32),
            beta=np.float64(self.beta),
            points_x=ok["x_m"].to_numpy(float),
            points_y=ok["y_m"].to_numpy(float),
            points_surface=ok["surface_z_m"].to_numpy(float),
            points_kappa=ok["kappa_N_per_m_beta"].to_numpy(float),
            points_lambda=ok["lambda_N_s_per_m_beta1"].to_numpy(float),
        )


def map_axis(lo: float, hi: float, resolution_m: float) -> np.ndarray:
    """lo, lo + r, ... up to hi (within 1e-9 m), the map grid along one axis."""
    if not (np.isfinite(resolution_m) and resolution_m > 0):
        raise VicDrakeError(f"map resolution must be > 0, got {resolution_m!r}")
    n = int(np.floor((hi - lo) / resolution_m + 1e-6)) + 1
    return lo + resolution_m * np.arange(n)


def build_tissue_map(
    points,
    region_m,
    *,
    beta: float,
    resolution_m: float = 1e-4,
    surface_node_spacing_m: float = 5e-3,
    gp: GpMapParams | None = None,
    std_resolution_m: float = 1e-3,
    progress=None,
) -> TissueMap:
    """Surface fit and GP maps from fitted palpation points.

    Args:
        points: DataFrame with x_m, y_m, surface_z_m, kappa_N_per_m_beta,
            lambda_N_s_per_m_beta1 and ok (as
            :attr:`~vic_drake.estimation.campaign.CampaignResult.points`).
        region_m: (x_min, x_max, y_min, y_max) of the maps.
        beta: Hunt-Crossley exponent of the fits.
        resolution_m: map grid spacing (paper: 0.1 mm).
        surface_node_spacing_m: GRIDFIT node spacing; the surface is splined
            from the nodes onto the map grid.
        gp: GP settings.
        std_resolution_m: spacing on which the GP std is computed exactly
            (see :func:`predict_std_grid`).
        progress: optional callable(str).
    """
    from vic_drake.estimation.surface import grid_axis, gridfit

    say = progress or (lambda message: None)
    gp = gp or GpMapParams()
    ok = points[points["ok"]]
    if len(ok) < 4:
        raise VicDrakeError(f"a map needs at least 4 fitted points, got {len(ok)}")
    x_min, x_max, y_min, y_max = region_m
    if not (x_max > x_min and y_max > y_min):
        raise VicDrakeError(
            f"the map region must have positive extent, got {region_m!r}"
        )
    xs, ys = map_axis(x_min, x_max, resolution_m), map_axis(y_min, y_max, resolution_m)
    px, py = ok["x_m"].to_numpy(float), ok["y_m"].to_numpy(float)
    timings = {}

    t0 = time.perf_counter()
    fit = gridfit(
        px,
        py,
        ok["surface_z_m"].to_numpy(float),
        x_nodes=grid_axis(
            min(x_min, px.min()), max(x_max, px.max()), surface_node_spacing_m
        ),
        y_nodes=grid_axis(
            min(y_min, py.min()), max(y_max, py.max()), surface_node_spacing_m
        ),
    )
    surface = fit.on_grid(xs, ys)
    timings["surface_fit"] = time.perf_counter() - t0
    say(
        f"surface: GRIDFIT smoothness {fit.smoothness:.3g} (GCV), residual "
        f"{fit.residual_rms * 1e3:.3f} mm, {timings['surface_fit']:.1f} s"
    )

    step = max(1, int(round(std_resolution_m / resolution_m)))
    maps = {}
    for key, column in (
        ("kappa", "kappa_N_per_m_beta"),
        ("lam", "lambda_N_s_per_m_beta1"),
    ):
        t0 = time.perf_counter()
        model = fit_gp(px, py, _to_target(ok[column].to_numpy(float), gp), gp)
        t1 = time.perf_counter()
        mean, std = _from_target(
            *predict_grid(model, xs, ys, chunk_size=gp.chunk_size, std_step=step), gp
        )
        t2 = time.perf_counter()
        maps[key] = (mean, std, str(model.kernel_))
        timings[f"{key}_gp_fit"] = t1 - t0
        timings[f"{key}_gp_predict"] = t2 - t1
        say(
            f"{key}: {model.kernel_}; fit {t1 - t0:.1f} s, {xs.size} x {ys.size} map "
            f"{t2 - t1:.1f} s"
        )
    return TissueMap(
        x_m=xs,
        y_m=ys,
        surface_z_m=surface,
        kappa=maps["kappa"][0],
        lam=maps["lam"][0],
        kappa_std=maps["kappa"][1],
        lam_std=maps["lam"][1],
        beta=float(beta),
        points=points,
        surface_fit=fit,
        kappa_kernel=maps["kappa"][2],
        lam_kernel=maps["lam"][2],
        timings_s=timings,
    )


def find_ribs(
    x, profile, *, min_prominence_frac: float = 0.15, min_separation_m: float = 0.02
) -> np.ndarray:
    """x positions of the ribs: peaks of a kappa profile along x.

    A peak counts when its prominence is at least ``min_prominence_frac`` of
    the profile's range and it is at least ``min_separation_m`` from a
    higher one (scipy.signal.find_peaks). Peaks on the first or last sample
    cannot be told from an edge and are not reported.
    """
    from scipy.signal import find_peaks

    x, profile = np.asarray(x, float), np.asarray(profile, float)
    span = float(np.ptp(profile))
    if x.size < 3 or span <= 0:
        return np.zeros(0)
    dx = float(np.median(np.diff(x)))
    peaks, _ = find_peaks(
        profile,
        prominence=min_prominence_frac * span,
        distance=max(1, int(round(min_separation_m / dx))),
    )
    return x[peaks]


def band_profile(x_m, y_m, field, y_line: float, half_width_m: float) -> np.ndarray:
    """Mean of field[ix, iy] over |y - y_line| <= half_width_m, per x."""
    band = np.abs(np.asarray(y_m) - y_line) <= half_width_m + 1e-12
    if not band.any():
        band = np.abs(np.asarray(y_m) - y_line) == np.min(
            np.abs(np.asarray(y_m) - y_line)
        )
    return np.asarray(field)[:, band].mean(axis=1)


@dataclass(frozen=True)
class MapComparison:
    """A map against its phantom's truth over the map grid.

    Attributes:
        kappa_rmse_pct, lambda_rmse_pct: RMS of (est - true) / true, %.
        surface_rmse_mm: RMS of est - true surface height, mm.
        ribs_true, ribs_found: rib x positions, m (see :func:`compare_with_phantom`).
        rib_errors_m: |found - true| of each true rib's nearest found rib.
        y_line_m, band_m: the scan line the ribs are read on.
    """

    kappa_rmse_pct: float
    lambda_rmse_pct: float
    surface_rmse_mm: float
    ribs_true: tuple[float, ...]
    ribs_found: tuple[float, ...]
    rib_errors_m: tuple[float, ...]
    y_line_m: float
    band_m: float


def compare_with_phantom(
    tmap: TissueMap,
    phantom,
    *,
    y_line_m: float | None = None,
    band_m: float = 0.01,
    edge_m: float = 0.01,
    chunk_size: int = 200_000,
) -> MapComparison:
    """Errors of a map against the phantom it was palpated on.

    Ribs are peaks of kappa along x, averaged over ``y_line_m +- band_m``
    (default: the map's middle y). Truth: for a phantom with
    ``rib_centres_x`` (the synthetic chest) its rib centre lines at
    ``y_line_m``; otherwise (the measured map) the peaks that
    :func:`find_ribs` finds on the phantom's own kappa on the same grid and
    band. Ribs within ``edge_m`` of the map's x edges are left out of both
    lists (a peak at the edge cannot be located). The truth is sampled in
    blocks of about ``chunk_size`` grid points.
    """
    xs, ys = tmap.x_m, tmap.y_m
    # Sums of squared errors, accumulated over blocks of x-rows so the truth
    # of a 2 M-point map is never held whole.
    sums = np.zeros(3)
    rows = max(1, chunk_size // ys.size)
    for i0 in range(0, xs.size, rows):
        i1 = min(xs.size, i0 + rows)
        X, Y = np.meshgrid(xs[i0:i1], ys, indexing="ij")
        truth = phantom.sample(X, Y)
        sums += (
            np.sum(((tmap.kappa[i0:i1] - truth.kappa) / truth.kappa) ** 2),
            np.sum(((tmap.lam[i0:i1] - truth.lam) / truth.lam) ** 2),
            np.sum((tmap.surface_z_m[i0:i1] - truth.surface_z_m) ** 2),
        )
    n = xs.size * ys.size
    kappa_pct = float(100.0 * np.sqrt(sums[0] / n))
    lam_pct = float(100.0 * np.sqrt(sums[1] / n))
    surface_mm = float(1e3 * np.sqrt(sums[2] / n))
    y_line = float(np.mean([ys[0], ys[-1]])) if y_line_m is None else float(y_line_m)
    lo, hi = xs[0] + edge_m, xs[-1] - edge_m

    def inside(values):
        return tuple(float(v) for v in np.sort(values) if lo <= v <= hi)

    found = inside(find_ribs(xs, band_profile(xs, ys, tmap.kappa, y_line, band_m)))
    if hasattr(phantom, "rib_centres_x"):
        true = inside(np.asarray(phantom.rib_centres_x(y_line)).ravel())
    else:
        band = np.abs(ys - y_line) <= band_m + 1e-12
        if not band.any():
            band = np.abs(ys - y_line) == np.min(np.abs(ys - y_line))
        X, Y = np.meshgrid(xs, ys[band], indexing="ij")
        true_kappa = phantom.sample(X, Y).kappa
        true = inside(find_ribs(xs, true_kappa.mean(axis=1)))
    errors = tuple(
        float(np.min(np.abs(np.asarray(found) - t))) if found else float("nan")
        for t in true
    )
    return MapComparison(
        kappa_rmse_pct=kappa_pct,
        lambda_rmse_pct=lam_pct,
        surface_rmse_mm=surface_mm,
        ribs_true=true,
        ribs_found=found,
        rib_errors_m=errors,
        y_line_m=y_line,
        band_m=band_m,
    )
