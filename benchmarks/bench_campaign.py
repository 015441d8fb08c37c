"""Campaign throughput on Dask: runs per hour with 1 worker against 2.

Runs the same campaign (by default ``campaigns/smoke.yaml``, the first
``--runs`` runs) on a local Dask cluster of 1 and then 2 worker processes,
each in a fresh output folder, and prints for each: wall time (cluster
start to last row), runs per hour, and the ratio 2 workers / 1 worker (the
goal is >= 1.7). The machine's load average is printed with each figure:
other processes on the cores take their share.

    python benchmarks/bench_campaign.py [--spec campaigns/smoke.yaml] [--runs 16]
        [--workers 1,2] [--keep DIR]

Figures measured with it: docs/decisions.md, "Campaign throughput: 2 workers against 1".
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from common import comma_list, versions
from pydrake.common.yaml import yaml_dump_typed

from vic_drake.experiments.campaign import load_campaign_spec, read_rows, run_campaign
from vic_drake.experiments.campaign.spec import CampaignSpec


def _spec_with_runs(spec_path: Path, runs: int, folder: Path) -> Path:
    spec, base = load_campaign_spec(spec_path)
    grid = spec.grid_size or 1
    runs = max(grid, runs - runs % grid)
    trimmed = CampaignSpec(
        **{**spec.__dict__, "runs": runs, "base_scenario": str(base)}
    )
    path = folder / "spec.yaml"
    path.write_text(yaml_dump_typed(trimmed))
    return path


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--spec", default=str(Path(__file__).parents[1] / "campaigns" / "smoke.yaml")
    )
    p.add_argument("--runs", type=int, default=16)
    p.add_argument("--workers", default="1,2")
    p.add_argument("--keep", default=None, help="keep the campaign folders here")
    args = p.parse_args()
    workers = comma_list(p, "--workers", args.workers, int)
    print(versions())
    root = Path(args.keep or tempfile.mkdtemp(prefix="bench_campaign_"))
    root.mkdir(parents=True, exist_ok=True)
    spec = _spec_with_runs(Path(args.spec), args.runs, root)
    print(f"cores: {os.cpu_count()}, python {sys.version.split()[0]}, spec {args.spec}")
    rates = {}
    for n in workers:
        out = root / f"workers_{n}"
        shutil.rmtree(out, ignore_errors=True)
        t0 = time.perf_counter()
        load0 = os.getloadavg()[0]
        result = run_campaign(spec, out, workers=n)
        wall = time.perf_counter() - t0
        rate = result["finished"] / wall * 3600
        rates[n] = rate
        rows = read_rows(out)
        busy = rows["wall_s"].sum()
        print(
            f"{n} worker(s): {result['finished']} runs ({result['failed']} failed) in "
            f"{wall:.1f} s = {rate:.0f} runs/h (engine's own figure "
            f"{result['runs_per_hour']:.0f} runs/h); load average before/after "
            f"{load0:.2f}/{os.getloadavg()[0]:.2f}"
        )
        print(
            f"    mean run {rows['wall_s'].mean():.1f} s wall; runs in flight on "
            f"average {busy / wall:.2f} (of {n}): below n, the workers waited; "
            "at n with a low speed-up, the runs shared the cores with other work"
        )
    if 1 in rates and 2 in rates:
        print(
            f"speed-up 2 workers / 1 worker: {rates[2] / rates[1]:.2f}x (goal >= 1.7x)"
        )
    if not args.keep:
        shutil.rmtree(root, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
