"""``vic-drake map``: palpation campaign, surface fit and GP maps of a phantom.

Writes into ``--out``:

- ``maps.npz``: x, y (axes, m), surface (m), kappa, lambda, kappa_std,
  lambda_std on the map grid (see TissueMap.save_npz), and the points.
- ``points.csv``: the per-point fits with the phantom's truth.
- ``fig4_stiffness_damping.png``, ``fig5_surface_kappa.png``,
  ``gp_std.png``, ``map_vs_truth.png``.
- ``metrics.json``: exactly {"points", "kappa_rmse_pct", "lambda_rmse_pct",
  "surface_rmse_mm", "ribs_true", "ribs_found", "wall_s"}; ``--json``
  prints the same object (and nothing else) on stdout.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from vic_drake.commands.common import (
    Progress,
    add_data_dir_option,
    add_json_option,
    emit,
    to_json,
)
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.dask_cluster import add_cluster_arguments
from vic_drake.paths import check_not_a_run_folder, check_output_dir

MAX_MAP_POINTS = 20_000_000  # 2001 x 1001 at 0.1 mm over 20 x 10 cm is 2 M.
MAX_PALPATION_POINTS = 5_000
#: --phantom and --kernel choices (tissue.phantom.PHANTOM_KINDS and
#: estimation.gp_fit.KERNELS, written out: those modules load scikit-learn and
#: pydrake, which --help does not wait for; tests/commands/test_map.py checks
#: they agree).
PHANTOMS = ("synthetic", "measured")
GP_KERNELS = ("rbf", "matern")
METRIC_KEYS = (
    "points",
    "kappa_rmse_pct",
    "lambda_rmse_pct",
    "surface_rmse_mm",
    "ribs_true",
    "ribs_found",
    "wall_s",
)


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "map",
        help="simulate a palpation campaign on a phantom and build its GP tissue map",
        description=(
            "Palpates a phantom on a grid with simulated 1-DOF indenters (Drake), fits "
            "Hunt-Crossley kappa and lambda per point, reconstructs the surface "
            "(GRIDFIT-like, GCV smoothness) and interpolates kappa and lambda with "
            "Gaussian processes on a fine grid, then compares with the phantom's truth."
        ),
    )
    parser.add_argument(
        "--phantom",
        choices=PHANTOMS,
        default="synthetic",
        help="synthetic (default) or measured (the paper's map; needs the data)",
    )
    add_data_dir_option(parser)
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    add_json_option(parser)
    parser.add_argument(
        "--resolution-mm",
        type=float,
        default=0.1,
        help="map grid spacing, mm (default 0.1)",
    )
    parser.add_argument(
        "--spacing-cm",
        type=float,
        default=1.0,
        help="palpation grid spacing, cm (default 1)",
    )
    parser.add_argument(
        "--region",
        default=None,
        metavar="X0,X1,Y0,Y1",
        help="region to palpate and map, m, base frame; write --region=X0,... when X0 is "
        "negative (default: the measured map's grid; "
        "for the synthetic phantom the central 20 x 10 cm the paper palpated)",
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="sensor-noise seed (default 0)"
    )
    parser.add_argument(
        "--kernel",
        choices=GP_KERNELS,
        default="rbf",
        help="GP kernel shape: rbf (default) or matern",
    )
    parser.add_argument(
        "--time-step-ms",
        type=float,
        default=1.0,
        help="indenter plant time step, ms (default 1; 2 halves the simulation time)",
    )
    parser.add_argument(
        "--log-gp",
        action="store_true",
        help="model log kappa and log lambda in the GPs (default: the values, as the paper)",
    )
    add_cluster_arguments(parser, "the palpations' simulation", in_process_default=True)
    parser.add_argument(
        "--no-figures", action="store_true", help="skip the PNG figures"
    )
    parser.set_defaults(handler=run_map)


def _positive(value, option: str) -> float:
    if value is None or not math.isfinite(value) or value <= 0:
        raise VicDrakeError(f"{option} must be a finite number > 0; got {value!r}")
    return float(value)


def _parse_region(text: str) -> tuple[float, float, float, float]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 4 or not all(math.isfinite(v) for v in values):
        raise VicDrakeError(
            f"--region takes four numbers X0,X1,Y0,Y1 in m, e.g. -0.16,0.04,-0.41,-0.31; "
            f"got {text!r}"
        )
    x0, x1, y0, y1 = values
    if not (x1 > x0 and y1 > y0):
        raise VicDrakeError(f"--region needs X0 < X1 and Y0 < Y1; got {text!r}")
    return values


def _prepare_out(path: str) -> Path:
    check_not_a_run_folder(Path(path).expanduser())
    return check_output_dir(path, "--out")


def run_map(args) -> int:
    # Heavy (pydrake, scikit-learn): imported when the command runs, not when
    # the parser is built.
    from vic_drake.estimation.gp_fit import GpMapParams
    from vic_drake.experiments import (
        CampaignParams,
        default_region,
        grid_points,
        run_map_pipeline,
    )
    from vic_drake.systems.indenter import IndenterParams
    from vic_drake.tissue.phantom import load_phantom

    start = time.perf_counter()
    progress = Progress(True)
    resolution_m = _positive(args.resolution_mm, "--resolution-mm") * 1e-3
    spacing_m = _positive(args.spacing_cm, "--spacing-cm") * 1e-2
    time_step_s = _positive(args.time_step_ms, "--time-step-ms") * 1e-3
    if time_step_s > 0.002:
        raise VicDrakeError(
            f"--time-step-ms must be <= 2 (the sensor's 500 Hz period); got {args.time_step_ms!r}"
        )
    if args.seed < 0:
        raise VicDrakeError(f"--seed must be an integer >= 0; got {args.seed}")
    phantom = load_phantom(args.phantom, data_dir=args.data_dir)
    region = _parse_region(args.region) if args.region else default_region(phantom)
    n_map = (int((region[1] - region[0]) / resolution_m + 1e-6) + 1) * (
        int((region[3] - region[2]) / resolution_m + 1e-6) + 1
    )
    if n_map > MAX_MAP_POINTS:
        raise VicDrakeError(
            f"the map grid would have {n_map:,} points (> {MAX_MAP_POINTS:,}); raise "
            "--resolution-mm or shrink --region"
        )
    n_points = grid_points(region, spacing_m)[0].size
    if n_points > MAX_PALPATION_POINTS:
        raise VicDrakeError(
            f"{n_points} palpation points (> {MAX_PALPATION_POINTS}); raise --spacing-cm "
            "or shrink --region"
        )
    if n_points < 4:
        raise VicDrakeError(
            f"only {n_points} palpation points fit in the region at --spacing-cm "
            f"{args.spacing_cm:g}; a map needs at least 4"
        )
    out = _prepare_out(args.out)  # Made once the options are known to be good.

    mapped = run_map_pipeline(
        phantom,
        CampaignParams(
            indenter=IndenterParams(time_step_s=time_step_s),
            spacing_m=spacing_m,
            region_m=region,
            seed=args.seed,
            workers=args.workers,
        ),
        resolution_m=resolution_m,
        gp=GpMapParams(kernel=args.kernel, seed=args.seed, log_target=args.log_gp),
        progress=progress,
        scheduler=args.scheduler,
    )
    campaign, tmap, comparison = mapped.campaign, mapped.tissue_map, mapped.comparison
    tmap.save_npz(out / "maps.npz")
    campaign.points.to_csv(out / "points.csv", index=False)
    if not args.no_figures:
        _figures(tmap, phantom, comparison, out)
        progress(f"figures written to {out}")
    result = {
        "points": int(campaign.points["ok"].sum()),
        "kappa_rmse_pct": comparison.kappa_rmse_pct,
        "lambda_rmse_pct": comparison.lambda_rmse_pct,
        "surface_rmse_mm": comparison.surface_rmse_mm,
        "ribs_true": list(comparison.ribs_true),
        "ribs_found": list(comparison.ribs_found),
        "wall_s": time.perf_counter() - start,
    }
    assert tuple(result) == METRIC_KEYS
    (out / "metrics.json").write_text(to_json(result) + "\n")
    details = {
        "phantom": args.phantom,
        "region_m": list(mapped.region_m),
        "spacing_m": spacing_m,
        "resolution_m": resolution_m,
        "palpated": len(campaign.points),
        "lag_s": campaign.lag_s,
        "rib_errors_m": list(comparison.rib_errors_m),
        "rib_line_y_m": comparison.y_line_m,
        "surface_smoothness": tmap.surface_fit.smoothness,
        "kappa_kernel": tmap.kappa_kernel,
        "lambda_kernel": tmap.lam_kernel,
        "timings_s": {
            "simulate": campaign.simulate_s,
            "fit_points": campaign.fit_s,
            **tmap.timings_s,
        },
    }
    (out / "details.json").write_text(to_json(details) + "\n")
    human = (
        f"{result['points']} points on the {args.phantom} phantom; kappa RMSE "
        f"{result['kappa_rmse_pct']:.2f} %, lambda RMSE {result['lambda_rmse_pct']:.2f} %, "
        f"surface RMSE {result['surface_rmse_mm']:.3f} mm; ribs true "
        f"{_cm(result['ribs_true'])} cm, found {_cm(result['ribs_found'])} cm; "
        f"{result['wall_s']:.1f} s; written to {out}"
    )
    emit(result, args.json, human)
    return 0


def _cm(values) -> str:
    return "[" + ", ".join(f"{100 * v:.1f}" for v in values) + "]"


def _figures(tmap, phantom, comparison, out: Path) -> None:
    from vic_drake.reproduce.plots.maps import (
        plot_map_vs_truth,
        plot_std_maps,
        plot_stiffness_damping_maps,
        plot_surface_kappa,
    )

    plot_stiffness_damping_maps(tmap, save_path=out / "fig4_stiffness_damping.png")
    plot_surface_kappa(tmap, save_path=out / "fig5_surface_kappa.png")
    plot_std_maps(tmap, save_path=out / "gp_std.png")
    truth = _decimated_truth_kappa(tmap, phantom, max_pixels=600)
    plot_map_vs_truth(
        truth[0],
        truth[1],
        ribs_true=comparison.ribs_true,
        ribs_found=comparison.ribs_found,
        y_line_m=comparison.y_line_m,
        save_path=out / "map_vs_truth.png",
    )


def _decimated_truth_kappa(tmap, phantom, *, max_pixels: int):
    """(map decimated to <= max_pixels per axis, the phantom's kappa on its grid)."""
    from dataclasses import replace

    sx = max(1, int(np.ceil(tmap.x_m.size / max_pixels)))
    sy = max(1, int(np.ceil(tmap.y_m.size / max_pixels)))
    small = replace(
        tmap,
        x_m=tmap.x_m[::sx],
        y_m=tmap.y_m[::sy],
        surface_z_m=tmap.surface_z_m[::sx, ::sy],
        kappa=tmap.kappa[::sx, ::sy],
        lam=tmap.lam[::sx, ::sy],
        kappa_std=tmap.kappa_std[::sx, ::sy],
        lam_std=tmap.lam_std[::sx, ::sy],
    )
    X, Y = np.meshgrid(small.x_m, small.y_m, indexing="ij")
    return small, phantom.sample(X, Y).kappa


__all__ = ["METRIC_KEYS", "register", "run_map"]
