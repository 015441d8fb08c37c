"""How well does compare-real reproduce a log whose truth is known?

compare-real is run on real logs we do not have, among them phantoms moved
by hand with contact lost and regained several times. This builds such a log
in simulation, where the phantom's motion is known, and feeds it back:

1. the scenario compare-real builds for a shared log (``--log``: its
   controller and settings, identified from the log, on the measured map
   raised by the rig's surface offset), with random hand motion instead of
   the log's own: ``--events`` times the phantom is lifted 5-15 mm, then
   dropped 6-12 mm below its rest in 0.12-0.25 s (faster than the probe
   follows) and brought back (seeded, ``--seeds``);
2. that scan written as the rig's ROS 2 bag (31 columns for VS-CF/VS-VF,
   9 for CS/CF), with no nominal sibling beside it;
3. ``compare_real`` on the bag, as ``vic-drake compare-real BAG --json``.

Printed per run: the motion estimate against the truth (RMS in contact and
out of contact, mm), the replayed motion against the truth, and the
contract figures (force RMSE, peaks, contact loss of the bag vs of the
replay, and the overlap). A perfect method gives force RMSE 0 and the whole
loss reproduced at the same time; what it gives is the ceiling of the
method on logs of that kind. Needs the data (the measured map).

    python benchmarks/compare_real_roundtrip.py [--log NAME] [--seeds 0,1]
        [--events 5] [--keep DIR]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from common import versions

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.contact import contact_mask
from vic_drake.analysis.phantom_motion import estimate_phantom_motion
from vic_drake.experiments.compare_real import compare_real
from vic_drake.experiments.real_logs import scenario_from_real_log
from vic_drake.experiments.rig_log import write_scan_bag
from vic_drake.experiments.scan_run import run_scan
from vic_drake.paths import has_data, resolve_data_dir
from vic_drake.realdata import RIG_SURFACE_OFFSET_M, read_bag
from vic_drake.scenario import DisturbanceConfig, PhantomLift
from vic_drake.tissue.phantom import load_phantom
from vic_drake.tissue.phantom.distorted import with_map_errors

#: The first event starts this long after the log's first contact, s (the
#: surface calibration reads the rest surface at the first contact), and
#: the events are this far apart, s.
FIRST_EVENT_AFTER_CONTACT_S = 2.0
EVENT_SPACING_S = 3.6


def hand_lifts(seed: int, events: int, first_s: float) -> list[PhantomLift]:
    """Random hand motion from ``first_s``: each event a lift, then a fast
    drop below rest."""
    rng = np.random.default_rng(seed)
    lifts = []
    for k in range(events):
        t = first_s + k * EVENT_SPACING_S
        lifts.append(
            PhantomLift(
                start_s=round(t, 3),
                height_m=round(rng.uniform(0.005, 0.015), 4),
                rise_s=round(rng.uniform(0.3, 0.8), 3),
                hold_s=round(rng.uniform(0.3, 1.0), 3),
                fall_s=round(rng.uniform(0.3, 0.6), 3),
            )
        )
        lifts.append(
            PhantomLift(
                start_s=round(t + 2.0, 3),
                height_m=-round(rng.uniform(0.006, 0.012), 4),
                rise_s=round(rng.uniform(0.12, 0.25), 3),
                hold_s=round(rng.uniform(0.3, 0.8), 3),
                fall_s=round(rng.uniform(0.3, 0.6), 3),
            )
        )
    return lifts


def one_run(
    data_dir: Path, log: str, seed: int, events: int, out_dir: Path, keep: bool
) -> dict:
    raw = read_bag(data_dir / "experiments" / log)
    contact = contact_mask(real_to_canonical(raw))
    first_s = float(raw["t_s"].to_numpy()[np.argmax(contact)] - raw["t_s"].iloc[0])
    lifts = hand_lifts(seed, events, first_s + FIRST_EVENT_AFTER_CONTACT_S)
    end_s = lifts[-1].start_s + lifts[-1].rise_s + lifts[-1].hold_s + lifts[-1].fall_s
    duration_s = min(float(raw["t_s"].iloc[-1] - raw["t_s"].iloc[0]), end_s + 2.0)
    scenario = scenario_from_real_log(
        raw, name=f"hand_{log}_{seed}", disturbance=DisturbanceConfig(lifts=lifts)
    )
    published = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    tissue = with_map_errors(published, surface_offset_m=RIG_SURFACE_OFFSET_M)
    # The controller reads the published map, as on the rig.
    scenario.variations.map_errors.surface_offset_m = -RIG_SURFACE_OFFSET_M
    scenario.validate()
    truth = run_scan(scenario, phantom=tissue, duration_s=duration_s)
    bag = write_scan_bag(truth, out_dir / f"hand_{log}_{seed}")
    out, sim, real = compare_real(bag, data_dir=data_dir, return_frames=True)
    if keep:
        truth.df.to_pickle(out_dir / f"hand_{log}_{seed}_truth.pkl")
        sim.to_pickle(out_dir / f"hand_{log}_{seed}_replay.pkl")
    # The estimate and the replay against the truth, on the bag's clock.
    t = real["t_s"].to_numpy()
    lift = np.interp(
        t, truth.df["t_s"].to_numpy(), truth.df["phantom_lift_m"].to_numpy()
    )
    est = estimate_phantom_motion(real, published)
    measured = est["measured"].to_numpy()
    err = est["phantom_lift_m"].to_numpy() - lift
    after = t >= t[np.argmax(measured)]
    gap = after & ~measured
    replayed = np.interp(t, sim["t_s"].to_numpy(), sim["phantom_lift_m"].to_numpy())
    # Compare only where both exist and the motion has started to matter.
    live = after & (t <= sim["t_s"].iloc[-1])

    def rms(v):
        return float(1e3 * np.sqrt(np.mean(v**2))) if v.size else float("nan")

    return {
        "seed": seed,
        "first_event_s": lifts[0].start_s,
        "controller": out["controller"],
        "true_motion_max_mm": float(1e3 * np.max(np.abs(lift))),
        "est_rms_contact_mm": rms(err[after & measured]),
        "est_rms_gap_mm": rms(err[gap]),
        "replay_rms_mm": rms((replayed - lift)[live]),
        "force_rmse_N": out["force_rmse_N"],
        "peak_sim_N": out["force_peak_sim_N"],
        "peak_real_N": out["force_peak_real_N"],
        "loss_sim_s": out["contact_loss_total_sim_s"],
        "loss_real_s": out["contact_loss_total_real_s"],
        "loss_overlap_s": out["contact_loss_overlap_s"],
        "surface_offset_mm": out["surface_offset_mm"],
        "truth_offset_mm": 1e3 * RIG_SURFACE_OFFSET_M,
        "wall_s": None,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", default="test_nardi_matForce_lowR")
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--events", type=int, default=5)
    parser.add_argument("--data-dir", default=None)
    parser.add_argument(
        "--keep",
        default=None,
        help="folder to keep the bags in, with the true and the replayed scans (pickles)",
    )
    args = parser.parse_args()
    try:
        seeds = [int(s) for s in args.seeds.split(",") if s.strip()]
    except ValueError:
        parser.error(f"--seeds takes comma-separated integers; got {args.seeds!r}")
    if not seeds:
        parser.error("--seeds: give at least one seed")
    if not 1 <= args.events <= 8:
        parser.error(f"--events takes an integer from 1 to 8; got {args.events}")
    if not has_data(args.data_dir):
        sys.exit("this benchmark needs the data (the measured map); see README")
    data_dir = resolve_data_dir(args.data_dir)
    if not (data_dir / "experiments" / args.log).is_dir():
        parser.error(f"--log: no log {args.log!r} in {data_dir / 'experiments'}")
    print(versions())
    keep = Path(args.keep) if args.keep else None
    with tempfile.TemporaryDirectory() as tmp:
        out_dir = keep or Path(tmp)
        out_dir.mkdir(parents=True, exist_ok=True)
        for seed in seeds:
            t0 = time.perf_counter()
            row = one_run(
                data_dir, args.log, seed, args.events, out_dir, keep is not None
            )
            row["wall_s"] = round(time.perf_counter() - t0, 1)
            print(" ".join(f"{k}={_fmt(v)}" for k, v in row.items()), flush=True)


def _fmt(v):
    return f"{v:.3f}" if isinstance(v, float) else str(v)


if __name__ == "__main__":
    main()
