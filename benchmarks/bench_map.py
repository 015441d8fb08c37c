"""Timing of the whole map pipeline (prints figures; no asserts).

    python benchmarks/bench_map.py [--data-dir DIR] [--phantom measured]
        [--resolution-mm 0.1] [--workers 1] [--time-step-ms 1] [--designs]

Runs what ``vic-drake map`` runs on the measured map's region (21 x 11 = 231
palpation points at 1 cm; the synthetic phantom on the same region when the
data is absent): the palpation campaign (simulation, per-point fits), the
GRIDFIT surface with GCV, the GP fits of kappa and lambda, their 0.1 mm maps
(2011 x 1021 points) with std, the comparison with the phantom and the
figures. Prints the wall time of every stage and the peak resident memory.

``--designs`` also times the two ways to simulate many palpations: one
indenter-bank diagram holding N indenters (what the campaign does) against
one single-indenter diagram re-simulated per point with a fresh Context.
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time

import numpy as np
from common import versions


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def designs(phantom, n: int) -> None:
    from pydrake.systems.analysis import Simulator

    from vic_drake.experiments import CampaignParams, MakeIndenterDiagram, grid_points

    params = CampaignParams()
    pal = params.palpation
    x, y = grid_points(phantom.bounds, 0.01)
    x, y = x[:n], y[:n]
    t = phantom.sample(x, y)
    t_end = pal.max_approach_s + pal.duration_s

    t0 = time.perf_counter()
    bank = MakeIndenterDiagram(n, beta=phantom.beta)
    context = bank.diagram.CreateDefaultContext()
    bank.set_points(
        context,
        surface_z=t.surface_z_m,
        kappa=t.kappa,
        lam=t.lam,
        start_z=t.surface_z_m + pal.start_clearance_m,
        seed=0,
    )
    Simulator(bank.diagram, context).AdvanceTo(t_end)
    bank_s = time.perf_counter() - t0

    t0 = time.perf_counter()
    single = MakeIndenterDiagram(1, beta=phantom.beta)
    simulator = Simulator(single.diagram)
    for i in range(n):
        context = single.diagram.CreateDefaultContext()
        single.set_points(
            context,
            surface_z=t.surface_z_m[i : i + 1],
            kappa=t.kappa[i : i + 1],
            lam=t.lam[i : i + 1],
            start_z=t.surface_z_m[i : i + 1] + pal.start_clearance_m,
            seed=i,
        )
        simulator.reset_context(context)
        simulator.Initialize()
        simulator.AdvanceTo(t_end)
    single_s = time.perf_counter() - t0
    print(f"design: {n} points, {t_end:.1f} s simulated each")
    print(
        f"  one bank of {n} indenters:      {bank_s:7.2f} s  ({1e3 * bank_s / n:6.1f} ms/point)"
    )
    print(
        f"  one diagram re-run per point:  {single_s:7.2f} s  "
        f"({1e3 * single_s / n:6.1f} ms/point)"
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", default=None)
    parser.add_argument(
        "--phantom",
        default=None,
        help="measured (default if the data is there) or synthetic",
    )
    parser.add_argument("--resolution-mm", type=float, default=0.1)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--time-step-ms", type=float, default=1.0)
    parser.add_argument("--designs", action="store_true")
    parser.add_argument("--no-figures", action="store_true")
    args = parser.parse_args(argv)
    print(versions())

    os.environ.setdefault("MPLBACKEND", "Agg")
    from vic_drake.analysis.map_compare import compare_with_phantom
    from vic_drake.estimation.tissue_map import build_tissue_map
    from vic_drake.experiments import CampaignParams, run_campaign
    from vic_drake.paths import has_data
    from vic_drake.tissue import GridPhantom, load_phantom

    kind = args.phantom or ("measured" if has_data(args.data_dir) else "synthetic")
    phantom = load_phantom(kind, data_dir=args.data_dir)
    if kind == "measured":
        region = tuple(float(v) for v in phantom.bounds)
    else:
        region = (
            tuple(float(v) for v in GridPhantom.from_data_dir(args.data_dir).bounds)
            if has_data(args.data_dir)
            else (-0.1587, 0.0423, -0.4145, -0.3125)
        )
    print(
        f"phantom {kind}, region {np.round(region, 4).tolist()} m, "
        f"{os.cpu_count()} CPUs, python {sys.version.split()[0]}"
    )

    if args.designs:
        designs(phantom, 40)

    wall0 = time.perf_counter()
    from vic_drake.systems.indenter import IndenterParams

    indenter = IndenterParams(time_step_s=args.time_step_ms * 1e-3)
    campaign = run_campaign(
        phantom,
        CampaignParams(region_m=region, workers=args.workers, indenter=indenter),
    )
    print(f"campaign: {len(campaign.points)} points")
    print(f"  simulate (indenter bank)      {campaign.simulate_s:7.2f} s")
    print(f"  fit points (HC, beta={campaign.beta:g})    {campaign.fit_s:7.2f} s")
    print(f"  peak RSS so far               {peak_rss_mb():7.0f} MB")
    tmap = build_tissue_map(
        campaign.points,
        region,
        beta=campaign.beta,
        resolution_m=args.resolution_mm * 1e-3,
    )
    print(
        f"maps: {tmap.x_m.size} x {tmap.y_m.size} = {tmap.x_m.size * tmap.y_m.size:,} points"
    )
    for stage, seconds in tmap.timings_s.items():
        print(f"  {stage:<28s}  {seconds:7.2f} s")
    t0 = time.perf_counter()
    comparison = compare_with_phantom(tmap, phantom)
    print(f"  compare with phantom          {time.perf_counter() - t0:7.2f} s")
    if not args.no_figures:
        import tempfile
        from pathlib import Path

        from vic_drake.commands.mapping import _figures

        t0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            _figures(tmap, phantom, comparison, Path(tmp))
        print(f"  figures (4 PNG)               {time.perf_counter() - t0:7.2f} s")
    wall = time.perf_counter() - wall0
    print(f"total wall                      {wall:7.2f} s")
    print(f"peak RSS                        {peak_rss_mb():7.0f} MB")
    print(
        f"kappa RMSE {comparison.kappa_rmse_pct:.2f} %, lambda RMSE "
        f"{comparison.lambda_rmse_pct:.2f} %, surface RMSE {comparison.surface_rmse_mm:.3f} mm, "
        f"ribs true {np.round(comparison.ribs_true, 4).tolist()}, found "
        f"{np.round(comparison.ribs_found, 4).tolist()}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
