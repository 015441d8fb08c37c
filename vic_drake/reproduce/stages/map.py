"""Stage ``map``: palpation campaign, GP maps of kappa and lambda, ribs (Fig. 4-5).

The campaign palpates the scan phantom in simulation; its GP kappa map gives
C3 "sim". The paper's own GP map (``phantom_map/``) gives C3 "real".
"""

from __future__ import annotations

import numpy as np

from vic_drake.analysis.ribs import rib_prominences
from vic_drake.realdata import read_phantom_map
from vic_drake.reproduce.context import RunContext, _write_log
from vic_drake.tissue import load_phantom

#: The region the paper palpated (the measured map's extent), m.
MAP_REGION_M = (-0.1587, 0.0423, -0.4145, -0.3125)


def stage_map(ctx: RunContext) -> dict:
    """Palpation campaign on a 1 cm grid, GP map of kappa and lambda, ribs.

    The campaign palpates the scan phantom (the measured map when the data is
    there, else the synthetic chest) in simulation; its GP kappa map gives C3
    "sim". The paper's own GP map (``phantom_map/``) gives C3 "real".
    """
    # Function-local: the campaign pulls in pydrake, the GP maps scikit-learn
    # and the plots matplotlib (heavy).
    from vic_drake.experiments import CampaignParams, run_map_pipeline
    from vic_drake.reproduce.plots.maps import (
        plot_maps_vs_paper,
        plot_stiffness_damping_maps,
        plot_surface_kappa,
    )

    out: dict = {}
    real_map = None
    if ctx.data_dir is not None:
        real_map = read_phantom_map(ctx.data_dir / "phantom_map")
    phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
    region = MAP_REGION_M
    if ctx.options.quick:  # A 5 cm band across the ribs (the ribs run along y).
        region = (region[0], region[1], -0.385, -0.335)
    params = CampaignParams(spacing_m=0.01, region_m=region)
    res = 0.001 if ctx.options.quick else 1e-4
    # The same pipeline as `vic-drake map`; the comparison with the phantom
    # is the stage's own (below, on a 1 mm subgrid).
    mapped = run_map_pipeline(
        phantom,
        params,
        resolution_m=res,
        compare=False,
        progress=lambda m: ctx.progress(f"  {m}"),
    )
    campaign, tmap = mapped.campaign, mapped.tissue_map
    _write_log(
        ctx,
        "campaign_points",
        campaign.points.drop(columns=["message"]),
        {
            "campaign_params": params,
            "phantom": ctx.phantom_kind,
            "lag_s": campaign.lag_s,
        },
    )
    pts = campaign.ok
    out["ribs_sim"] = rib_prominences(tmap.x_m, tmap.y_m, tmap.kappa)
    out["campaign"] = campaign
    out["tissue_map"] = tmap
    # Error of the estimated kappa against the phantom, on a 1 mm subgrid.
    step = max(1, int(round(1e-3 / res)))
    xs, ys = tmap.x_m[::step], tmap.y_m[::step]
    truth = phantom.sample(*np.meshgrid(xs, ys, indexing="ij"))
    kerr = tmap.kappa[::step, ::step] - truth.kappa
    out["kappa_rel_rmse"] = float(np.sqrt(np.mean(kerr**2)) / np.mean(truth.kappa))
    ctx.add_figure(
        "Fig. 4: GP maps of kappa and lambda",
        f"GP maps every {res * 1e3:g} mm from {len(pts)} palpations simulated on a 1 cm grid "
        f"of the {ctx.phantom_kind} phantom over x {100 * region[0]:.1f}..{100 * region[1]:.1f}"
        f" cm, y {100 * region[2]:.1f}..{100 * region[3]:.1f} cm (dots: palpation points).",
        plot_stiffness_damping_maps(tmap),
        "fig4_gp_maps.png",
    )
    ctx.add_figure(
        "Fig. 4 (comparison): estimated maps"
        + (" and the paper's measured map" if real_map is not None else ""),
        "The estimated maps with the detected ribs (red dotted lines)"
        + (
            "; bottom: the paper's own GP map, on the same colour scale per column"
            if real_map is not None
            else " (no paper's map in this run: the real data is absent)"
        )
        + ". kappa relative RMS error of the estimate against the phantom: "
        f"{out['kappa_rel_rmse']:.1%}.",
        plot_maps_vs_paper(
            tmap,
            real_map,
            ribs_m=out["ribs_sim"]["rib_position_m"],
            paper_ribs_m=rib_prominences(real_map.x_m, real_map.y_m, real_map.kappa)[
                "rib_position_m"
            ]
            if real_map is not None
            else (),
        ),
        "fig4_maps_vs_paper.png",
    )
    ctx.add_figure(
        "Fig. 5: surface with elasticity",
        "The GRIDFIT-like surface through the contact points, coloured by the kappa map "
        "(the paper's Fig. 5).",
        plot_surface_kappa(tmap),
        "fig5_surface_kappa.png",
    )
    return out
