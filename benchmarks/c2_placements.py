"""C2's verdict per palpation log under each window placement of Fig. 3's curve.

For each log, builds :func:`residual_vs_palpation_time` with one window per
length at the first in-contact sample ("first") and with windows starting
every ``--steps`` seconds along the log, combined by mean / rms / median,
and prints C2's per-log metric (Spearman, R^2, last/first; thresholds of
:mod:`vic_drake.analysis.claims.thresholds`) on the log as recorded and
trimmed: 1-3 s dropped after the first in-contact sample, 1-3 s dropped at
the end, the first 1-2 palpation cycles dropped. Each row names the approach
cycles the curve skipped (``skip_approach``); "first, approach kept" is the
curve counted from the first in-contact sample. ``--settle-fractions``
prints, per log as recorded, the cycles skipped and the verdict at each
settle fraction of :func:`~vic_drake.estimation.palpation.approach.palpation_start`.

    python benchmarks/c2_placements.py [--data-dir DIR] [--sim-dir REPRODUCE_OUT]
        [--steps 0.5,0.25,0.1] [--no-trims] [--settle-fractions 0.05,0.1,0.2]

``--sim-dir``: a ``vic-drake reproduce`` output folder holding
``logs/palpation_sim*.parquet`` (stage offline_sim); its relaxing-tissue and
plain-HC palpations are measured too.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from common import comma_list

from vic_drake.analysis.claims.offline import c2_decay
from vic_drake.estimation.palpation import PalpationData, compare_models, shift
from vic_drake.estimation.palpation.data import contact_mask, kinematics
from vic_drake.estimation.palpation.residual import residual_vs_palpation_time
from vic_drake.paths import has_data, resolve_data_dir

REAL_LOGS = {"test_soft_1hz": 1.0, "test_soft_2hz": 2.0, "test_soft_25hz": 2.5}


def real_logs(data_dir) -> dict:
    """{name: (aligned PalpationData, palpation frequency Hz)}."""
    from vic_drake.realdata import read_bag

    out = {}
    for name, hz in REAL_LOGS.items():
        d = PalpationData.from_frame(read_bag(data_dir / "palpation" / name))
        out[name] = (shift(d, compare_models(d).lag_s), hz)
    return out


def sim_logs(sim_dir, data_dir) -> dict:
    """The offline_sim stage's palpations, aligned by the simulated sensor lag."""
    import pandas as pd
    import yaml

    from vic_drake.tissue import load_phantom

    out = {}
    for path in sorted((sim_dir / "logs").glob("palpation_sim*.parquet")):
        cfg = yaml.safe_load(path.with_suffix(".yaml").read_text(encoding="utf-8"))
        params = cfg["campaign_params"]
        x, y = cfg["point_xy_m"]
        phantom = load_phantom(cfg["phantom"], data_dir=data_dir)
        surface = float(phantom.sample(np.array([x]), np.array([y])).surface_z_m[0])
        df = pd.read_parquet(path)
        d = PalpationData(
            t_s=df["t_s"].to_numpy(),
            z_m=df["z_m"].to_numpy(),
            force_N=df["force_z_N"].to_numpy(),
            surface_z_m=surface,
            z_target_m=df["z_target_m"].to_numpy(),
        )
        lag = params["sensor"]["lag_samples"] / params["sensor"]["rate_hz"]
        out[path.stem] = (shift(d, lag), params["palpation"]["frequency_hz"])
    return out


def variants(data: PalpationData, hz: float, trims: bool) -> dict:
    """The log as recorded and trimmed at either end or by whole cycles."""
    out = {"as recorded": data}
    if not trims:
        return out
    # The first in-contact sample, by the mask the curve uses.
    t_first = data.t_s[np.argmax(contact_mask(data, kinematics(data)))]
    for s in (1, 2, 3):
        out[f"start +{s} s"] = data.select(data.t_s >= t_first + s)
    for s in (1, 2, 3):
        out[f"end -{s} s"] = data.select(data.t_s <= data.t_s[-1] - s)
    for k in (1, 2):
        out[f"+{k} cycle"] = data.select(data.t_s >= t_first + k / hz + 1e-9)
    return out


def row(data: PalpationData, **kw) -> str:
    c = residual_vs_palpation_time(data, **kw)
    d, ok = c2_decay((c.window_s, c.relative))
    r5 = float(np.interp(5.0, c.window_s, c.relative))
    skipped = "-" if c.approach is None else c.approach.cycles_skipped
    return (
        f"skip {skipped} {'pass' if ok else 'FAIL'} rho {d['spearman']:+.2f} R2 {d['r2']:.2f} "
        f"last/first {d['ratio_last_first']:.2f} tau {d['tau_s']:5.1f} s | "
        f"r(0.5 s) {c.relative[0]:.4f} r(5 s) {r5:.4f} r(all) {c.relative[-1]:.4f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data-dir", default=None)
    parser.add_argument("--sim-dir", default=None)
    parser.add_argument("--steps", default="0.5,0.25,0.1")
    parser.add_argument("--no-trims", action="store_true")
    parser.add_argument("--settle-fractions", default=None)
    args = parser.parse_args()
    steps = comma_list(parser, "--steps", args.steps, float)
    fractions = (
        comma_list(parser, "--settle-fractions", args.settle_fractions, float)
        if args.settle_fractions
        else None
    )
    data_dir = resolve_data_dir(args.data_dir)
    logs = real_logs(data_dir) if has_data(data_dir) else {}
    if args.sim_dir:
        logs.update(sim_logs(Path(args.sim_dir), data_dir))
    if fractions:
        for name, (data, hz) in logs.items():
            print(f"== {name} ({hz:g} Hz): settle fraction -> cycles skipped, C2")
            for f in fractions:
                print(f"  {f:<5g} {row(data, settle_fraction=f)}")
        return
    methods = {
        "first": dict(start_step_s=None),
        "first, approach kept": dict(start_step_s=None, skip_approach=False),
    }
    for step in steps:
        for average in ("mean", "rms", "median"):
            methods[f"{average} {step:g} s"] = dict(start_step_s=step, average=average)
    for name, (data, hz) in logs.items():
        print(f"== {name} ({hz:g} Hz, {data.duration_s:.1f} s)")
        for label, kw in methods.items():
            for vname, v in variants(data, hz, not args.no_trims).items():
                print(f"  {label:<14} {vname:<12} {row(v, **kw)}")


if __name__ == "__main__":
    main()
