"""compare-real on a simulated log of a phantom moved by hand, whose motion is known.

compare-real is run on real logs that the project does not have, among them
phantoms moved by hand with contact lost and regained several times.
:func:`hand_moved_roundtrip` builds such a log in simulation and feeds it
back: the scenario compare-real builds for a shared log (its controller and
settings identified from the log, on the measured map raised by the rig's
surface offset, the controller reading the published map) with random hand
motion (:func:`hand_lifts`) instead of the log's own; the scan written as the
rig's ROS 2 bag (31 columns for VS-CF/VS-VF, 9 for CS/CF, no nominal sibling
beside it); :func:`~vic_drake.experiments.compare_real.compare_real` on that
bag. A perfect method gives force RMSE 0 and the whole loss reproduced at the
same time; what it gives is the method's ceiling on logs of that kind
(``benchmarks/compare_real_roundtrip.py`` prints it per seed).
"""

from pathlib import Path

import numpy as np

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.contact import contact_mask
from vic_drake.analysis.phantom_motion import estimate_phantom_motion
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.compare_real import compare_real
from vic_drake.experiments.real_logs import scenario_from_real_log
from vic_drake.experiments.rig_log import write_scan_bag
from vic_drake.experiments.scan_run import run_scan
from vic_drake.realdata import RIG_SURFACE_OFFSET_M, read_bag
from vic_drake.scenario import DisturbanceConfig, PhantomLift
from vic_drake.tissue.phantom import load_phantom
from vic_drake.tissue.phantom.distorted import with_map_errors

#: Most hand events a round trip takes.
MAX_EVENTS = 8

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


def hand_moved_roundtrip(
    data_dir: Path,
    log: str,
    seed: int,
    events: int,
    out_dir: Path,
    *,
    keep: bool = False,
) -> dict:
    """One round trip on the shared log ``log`` with ``events`` hand events
    (seeded by ``seed``); the bag (and with ``keep`` the true and replayed
    scans, as pickles) is written in ``out_dir``.

    Returns:
        dict: seed, first_event_s, controller; the motion estimate against
        the truth, mm (true_motion_max_mm, est_rms_contact_mm,
        est_rms_gap_mm, replay_rms_mm); compare-real's motion_significance
        and motion_replayed (``phantom_motion_*``), force_rmse_N,
        peak_sim_N / peak_real_N ("real" is the bag), loss_sim_s /
        loss_real_s / loss_overlap_s, surface_offset_mm against
        truth_offset_mm.

    Raises:
        VicDrakeError: ``events`` out of 1..MAX_EVENTS or no such log.
    """
    if (
        isinstance(events, bool)
        or not isinstance(events, int)
        or not 1 <= events <= MAX_EVENTS
    ):
        raise VicDrakeError(
            f"events must be an integer from 1 to {MAX_EVENTS}; got {events!r}"
        )
    bag_in = Path(data_dir) / "experiments" / log
    if not bag_in.is_dir():
        raise VicDrakeError(f"no log {log!r} in {str(bag_in.parent)!r}")
    raw = read_bag(bag_in)
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
    # The estimate (against the published map; compare-real keeps its own)
    # and the replay against the truth, on the bag's clock.
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
        "motion_significance": out["phantom_motion_significance"],
        "motion_replayed": out["phantom_motion_replayed"],
        "force_rmse_N": out["force_rmse_N"],
        "peak_sim_N": out["force_peak_sim_N"],
        "peak_real_N": out["force_peak_real_N"],
        "loss_sim_s": out["contact_loss_total_sim_s"],
        "loss_real_s": out["contact_loss_total_real_s"],
        "loss_overlap_s": out["contact_loss_overlap_s"],
        "surface_offset_mm": out["surface_offset_mm"],
        "truth_offset_mm": 1e3 * RIG_SURFACE_OFFSET_M,
    }


__all__ = ["MAX_EVENTS", "hand_lifts", "hand_moved_roundtrip"]
