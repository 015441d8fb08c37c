"""Figures of the tissue map: Fig. 4 (kappa and lambda GP maps), Fig. 5
(surface coloured by kappa), the GP std maps and map-versus-truth panels.

Every function takes a :class:`~vic_drake.estimation.gp_maps.TissueMap` and
returns a matplotlib Figure; the only I/O is the optional ``save_path``.
Axes are the robot base frame in cm. Maps finer than ``max_pixels`` per axis
are decimated for drawing only.
"""

from __future__ import annotations

import numpy as np
from matplotlib import cm, colormaps
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from vic_drake.estimation.gp_maps import TissueMap
from vic_drake.reproduce.plots.figure import new_figure

CMAP = "viridis"  # The paper's Fig. 4 uses MATLAB's parula; viridis is its analogue.


def _finish(fig: Figure, save_path) -> Figure:
    fig.tight_layout()
    if save_path is not None:
        fig.savefig(save_path, dpi=150)
    return fig


def _decimate(x, y, field, max_pixels: int):
    sx = max(1, int(np.ceil(x.size / max_pixels)))
    sy = max(1, int(np.ceil(y.size / max_pixels)))
    return x[::sx], y[::sy], np.asarray(field)[::sx, ::sy]


def _tissue_points(tmap: TissueMap):
    """(x, y) of the map's accepted palpation points, m."""
    ok = tmap.points[tmap.points["ok"]]
    return ok["x_m"], ok["y_m"]


def _panel(
    fig,
    ax,
    x_m,
    y_m,
    field,
    label: str,
    *,
    max_pixels: int,
    points_m=None,
    ribs_m=(),
    limits=(None, None),
):
    """One map on the (x, y) grid in cm, with optional points and rib lines;
    ``limits``: the colour scale's (min, max), None for the field's own."""
    x, y, f = _decimate(np.asarray(x_m), np.asarray(y_m), field, max_pixels)
    image = ax.imshow(
        f.T,
        origin="lower",
        extent=(100 * x[0], 100 * x[-1], 100 * y[0], 100 * y[-1]),
        cmap=CMAP,
        vmin=limits[0],
        vmax=limits[1],
        aspect="equal",
        interpolation="nearest",
    )
    if points_m is not None:
        px, py = points_m
        ax.plot(100 * np.asarray(px), 100 * np.asarray(py), "k.", ms=1.5, alpha=0.5)
    for xr in ribs_m:
        ax.axvline(100 * xr, color="r", ls=":", lw=1)
    ax.set_xlabel("x [cm]")
    ax.set_ylabel("y [cm]")
    # A wide map in a narrow panel: few enough x ticks that labels never meet.
    ax.xaxis.set_major_locator(MaxNLocator(nbins=5))
    fig.colorbar(image, ax=ax, label=label, shrink=0.85)
    return image


def _map_panel(fig, ax, tmap: TissueMap, field, label, *, points, max_pixels):
    pts = _tissue_points(tmap) if points else None
    return _panel(
        fig, ax, tmap.x_m, tmap.y_m, field, label, max_pixels=max_pixels, points_m=pts
    )


def plot_stiffness_damping_maps(
    tmap: TissueMap,
    *,
    points: bool = True,
    max_pixels: int = 800,
    save_path=None,
    title: str | None = None,
) -> Figure:
    """Fig. 4: the GP maps of kappa (elasticity) and lambda (viscosity)."""
    fig = new_figure(figsize=(7.0, 6.5))
    axes = fig.subplots(2, 1)
    beta = tmap.beta
    _map_panel(
        fig,
        axes[0],
        tmap,
        tmap.kappa,
        f"κ [N/m^{beta:g}]",
        points=points,
        max_pixels=max_pixels,
    )
    axes[0].set_title("Elasticity κ (GP mean)")
    _map_panel(
        fig,
        axes[1],
        tmap,
        tmap.lam,
        f"λ [N s/m^{beta + 1:g}]",
        points=points,
        max_pixels=max_pixels,
    )
    axes[1].set_title("Viscosity λ (GP mean)")
    if title:
        fig.suptitle(title)
    return _finish(fig, save_path)


def plot_std_maps(
    tmap: TissueMap, *, points: bool = True, max_pixels: int = 800, save_path=None
) -> Figure:
    """Posterior std of the kappa and lambda GP maps."""
    fig = new_figure(figsize=(7.0, 6.5))
    axes = fig.subplots(2, 1)
    _map_panel(
        fig,
        axes[0],
        tmap,
        tmap.kappa_std,
        "std κ",
        points=points,
        max_pixels=max_pixels,
    )
    axes[0].set_title("Elasticity κ: GP posterior std")
    _map_panel(
        fig, axes[1], tmap, tmap.lam_std, "std λ", points=points, max_pixels=max_pixels
    )
    axes[1].set_title("Viscosity λ: GP posterior std")
    return _finish(fig, save_path)


def plot_surface_kappa(
    tmap: TissueMap,
    *,
    max_nodes: int = 150,
    azimuth_deg: float = 60.0,
    elevation_deg: float = 35.0,
    save_path=None,
) -> Figure:
    """Fig. 5: the GRIDFIT surface in 3D, coloured by the kappa map.

    The default view looks from +x (the paper rotates its view 180 deg from
    Fig. 4 to show the shoulder).
    """
    x, y, z = _decimate(tmap.x_m, tmap.y_m, tmap.surface_z_m, max_nodes)
    _, _, k = _decimate(tmap.x_m, tmap.y_m, tmap.kappa, max_nodes)
    X, Y = np.meshgrid(100 * x, 100 * y, indexing="ij")
    norm = Normalize(vmin=float(np.min(k)), vmax=float(np.max(k)))
    colors = colormaps[CMAP](norm(k))
    fig = new_figure(figsize=(7.5, 5.5))
    ax = fig.add_subplot(projection="3d")
    ax.plot_surface(
        X,
        Y,
        100 * z,
        facecolors=colors,
        rstride=1,
        cstride=1,
        linewidth=0,
        antialiased=False,
        shade=False,
    )
    ok = tmap.points[tmap.points["ok"]]
    ax.scatter(100 * ok["x_m"], 100 * ok["y_m"], 100 * ok["surface_z_m"], c="k", s=2)
    mappable = cm.ScalarMappable(norm=norm, cmap=CMAP)
    fig.colorbar(mappable, ax=ax, shrink=0.6, label=f"κ [N/m^{tmap.beta:g}]")
    ax.set_xlabel("x [cm]")
    ax.set_ylabel("y [cm]")
    ax.set_zlabel("z [cm]")
    ax.view_init(elev=elevation_deg, azim=azimuth_deg)
    ax.set_title("Surface (GRIDFIT) coloured by elasticity κ")
    return _finish(fig, save_path)


def plot_map_vs_truth(
    tmap: TissueMap,
    truth_kappa,
    *,
    ribs_true=(),
    ribs_found=(),
    y_line_m=None,
    max_pixels: int = 600,
    save_path=None,
) -> Figure:
    """True kappa, the map's kappa, their relative error, and the rib scan line."""
    fig = new_figure(figsize=(11.0, 6.0))
    axes = fig.subplots(2, 2)
    _map_panel(
        fig, axes[0, 0], tmap, truth_kappa, "κ", points=False, max_pixels=max_pixels
    )
    axes[0, 0].set_title("Phantom κ (truth)")
    _map_panel(
        fig, axes[0, 1], tmap, tmap.kappa, "κ", points=True, max_pixels=max_pixels
    )
    axes[0, 1].set_title("GP map κ")
    _map_panel(
        fig,
        axes[1, 0],
        tmap,
        100 * (tmap.kappa - truth_kappa) / truth_kappa,
        "error [%]",
        points=False,
        max_pixels=max_pixels,
    )
    axes[1, 0].set_title("Relative error of κ")
    ax = axes[1, 1]
    if y_line_m is None:
        y_line_m = 0.5 * (tmap.y_m[0] + tmap.y_m[-1])
    iy = int(np.argmin(np.abs(tmap.y_m - y_line_m)))
    ax.plot(100 * tmap.x_m, np.asarray(truth_kappa)[:, iy], "k-", label="truth")
    ax.plot(100 * tmap.x_m, tmap.kappa[:, iy], "C0-", label="GP map")
    for i, xr in enumerate(ribs_true):
        ax.axvline(100 * xr, color="k", ls=":", label="rib (truth)" if i == 0 else None)
    for i, xr in enumerate(ribs_found):
        ax.axvline(
            100 * xr, color="C3", ls="--", label="rib (found)" if i == 0 else None
        )
    ax.set_xlabel("x [cm]")
    ax.set_ylabel("κ")
    ax.set_title(f"κ along y = {100 * y_line_m:.1f} cm")
    ax.legend(fontsize=8)
    return _finish(fig, save_path)


def _shared_limits(fields) -> tuple[float, float]:
    fields = [np.asarray(f) for f in fields]
    return (
        float(min(np.nanmin(f) for f in fields)),
        float(max(np.nanmax(f) for f in fields)),
    )


def plot_maps_vs_paper(
    tmap: TissueMap,
    paper_map=None,
    *,
    ribs_m=(),
    paper_ribs_m=(),
    max_pixels: int = 400,
    save_path=None,
) -> Figure:
    """The estimated kappa and lambda maps with their ribs (top) and, when
    given, the paper's measured map (bottom), on the same cm axes and, per
    column, the same colour scale.

    Args:
        paper_map: anything with ``x_m``, ``y_m``, ``kappa`` and ``lam`` grids
            (:class:`~vic_drake.realdata.PhantomMapData`), or None.
        ribs_m, paper_ribs_m: rib x positions (m), drawn as red dotted lines.
    """
    maps = [(tmap, "estimated", ribs_m, _tissue_points(tmap))]
    if paper_map is not None:
        maps.append((paper_map, "the paper's measured map", paper_ribs_m, None))
    fig = new_figure(figsize=(11.0, 3.6 * len(maps)))
    axes = fig.subplots(len(maps), 2, squeeze=False)
    beta = tmap.beta
    kappa_limits = _shared_limits(m.kappa for m, *_ in maps)
    lam_limits = _shared_limits(m.lam for m, *_ in maps)
    for row, (m, name, ribs, pts) in zip(axes, maps):
        kw = dict(max_pixels=max_pixels)
        _panel(
            fig,
            row[0],
            m.x_m,
            m.y_m,
            m.kappa,
            f"κ [N/m^{beta:g}]",
            points_m=pts,
            ribs_m=ribs,
            limits=kappa_limits,
            **kw,
        )
        row[0].set_title(f"Elasticity κ, {name}", fontsize=9)
        _panel(
            fig,
            row[1],
            m.x_m,
            m.y_m,
            m.lam,
            f"λ [N s/m^{beta + 1:g}]",
            limits=lam_limits,
            **kw,
        )
        row[1].set_title(f"Viscosity λ, {name}", fontsize=9)
    return _finish(fig, save_path)
