"""The tissue map: surface (GRIDFIT) and GP maps of kappa and lambda (Fig. 4-5).

:func:`build_tissue_map` turns the fitted palpation points of a campaign into
a :class:`TissueMap` on a regular grid: the surface by
:func:`~vic_drake.estimation.surface.gridfit` of the contact heights, kappa
and lambda by one GP each (:mod:`vic_drake.estimation.gp_fit`), evaluated
every 0.1 mm by default as in the paper.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.gp_fit import GpMapParams, _from_target, _to_target, fit_gp
from vic_drake.estimation.gp_predict import predict_grid
from vic_drake.estimation.surface import grid_axis, gridfit


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
            :attr:`~vic_drake.experiments.palpation_campaign.CampaignResult.points`).
        region_m: (x_min, x_max, y_min, y_max) of the maps.
        beta: Hunt-Crossley exponent of the fits.
        resolution_m: map grid spacing (paper: 0.1 mm).
        surface_node_spacing_m: GRIDFIT node spacing; the surface is splined
            from the nodes onto the map grid.
        gp: GP settings.
        std_resolution_m: spacing on which the GP std is computed exactly
            (see :func:`~vic_drake.estimation.gp_predict.predict_std_grid`).
        progress: optional callable(str).
    """
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
