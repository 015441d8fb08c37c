"""What ``vic-drake scan`` checks and prints: the scenario file, the duration,
the metrics (the scan's and the campaign's) and the human summary.

Two forces are reported, under distinct names. ``force_peak_N`` (and
``force_range_N``, ``force_rmse_N``) is the force sensor's pressing force,
with its noise and lag; the scenario's ``variations.sensor_faults`` act after
the sensor, on what the controller reads, so they are not in it. ``campaign_metrics`` holds a
campaign row's metrics (:func:`vic_drake.experiments.campaign.run_metrics`):
its ``peak_force_N`` is the tissue's force on the probe (the force on the
patient), so a campaign run replayed with ``vic-drake scan`` prints the peak
the campaign reported.
"""

from __future__ import annotations

import math
from pathlib import Path

from vic_drake.commands.common import fmt_number
from vic_drake.paper import CONTACT_THRESHOLD_N
from vic_drake.paths import (
    CAMPAIGN_SCENARIOS_DIR,
    CAMPAIGN_SPEC_FILE,
)

SCAN_DESCRIPTION = (
    "Simulates one scenario file (the station, phantom, controller, trajectory "
    "and variations of a scan; diagrams/*.yaml are the paper's runs) and prints "
    "its metrics. Two forces, under distinct names: the sensor's pressing force "
    "(force_peak_N, force_range_N, force_rmse_N; with the sensor's noise and lag, "
    "before the scenario's sensor_faults, which act on the controller's input) and, in campaign_metrics, a campaign row's metrics, whose "
    "peak_force_N is the tissue's force on the patient (a campaign run replayed "
    "here prints the campaign's peak). force_range_N and force_rmse_N cover the "
    "scan window (first contact + 1 s until the final lift; null when a short "
    "run has none). --out saves the log and the exact scenario beside it; --bag "
    "writes the log as a ROS 2 bag in the real rig's layout."
)


def campaign_force_limit(path: Path) -> tuple[float, str]:
    """(force limit, where it came from) for a scenario file.

    A campaign run's scenario (``DIR/scenarios/run_*.yaml`` beside
    ``DIR/spec.yaml``) takes the campaign's ``force_limit_N``; any other
    the campaigns' default (``CampaignSpec.force_limit_N``).
    """
    # Here, not at the top: the campaign package costs ~0.9 s to import, and
    # every vic-drake command builds this module's parser.
    from vic_drake.experiments.campaign.spec import CampaignSpec

    spec = path.resolve().parent.parent / CAMPAIGN_SPEC_FILE
    if path.resolve().parent.name == CAMPAIGN_SCENARIOS_DIR and spec.is_file():
        import yaml

        try:
            value = float(yaml.safe_load(spec.read_text())["force_limit_N"])
        except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError):
            value = math.nan
        if math.isfinite(value) and value > 0:
            return value, f"the campaign's {str(spec)!r}"
    return float(CampaignSpec.force_limit_N), "the campaigns' default"


def scan_metrics_dict(scenario, result, path: Path, force_limit_N=None) -> dict:
    """The scan command's result: its metrics, then the campaign's.

    The first keys are the command's documented output (unchanged);
    ``scan_window_s`` (null without one), ``campaign_metrics`` and
    ``watchdog_channel`` ("x", "y" or "z": the stuck force channel that
    stopped the scan; "all": the sensor died, every channel frozen; null if
    the watchdog did not stop it) follow.
    """
    import numpy as np

    from vic_drake.analysis import contact, scan_metrics
    from vic_drake.control.references import has_tank
    from vic_drake.experiments.campaign import run_metrics

    df = result.df
    controller = scenario.controller.reference.controller
    t = df["t_s"].to_numpy(float)
    # The scan ends where the watchdog stopped it: after that the probe
    # lifts away from a target z_d_m that does not show the lift.
    stopped = math.isfinite(result.watchdog_trip_s)
    driven = t < result.watchdog_trip_s if stopped else None
    window = contact.scan_window(df)
    if stopped:
        window &= driven
    if force_limit_N is None:
        force_limit_N, limit_source = campaign_force_limit(path)
    else:
        limit_source = "--force-limit"
    tank = has_tank(scenario.controller.reference)
    with np.errstate(all="ignore"):
        campaign = run_metrics(
            df,
            force_limit_N=force_limit_N,
            has_tank=tank,
            stop_s=result.watchdog_trip_s,
        )
    campaign["watchdog_trip_s"] = result.watchdog_trip_s
    campaign["tank_floor_J"] = (
        float(scenario.controller.tank.min_energy_J) if tank else float("nan")
    )
    campaign["force_limit_N"] = float(force_limit_N)
    campaign["force_limit_source"] = limit_source
    return {
        "scenario": scenario.name,
        "controller": controller,
        "duration_s": result.sim_s,
        "rtf": result.rtf,
        # CS has no force reference: its RMSE against one is undefined.
        "force_rmse_N": None
        if controller == "cs"
        else scan_metrics.force_rmse_N(df, mask=window),
        "force_range_N": list(scan_metrics.force_range_N(df, mask=window)),
        "force_peak_N": scan_metrics.peak_force_N(df),
        "tank_min_J": campaign["tank_min_J"],
        "contact_loss_s": [
            list(i) for i in contact.contact_loss_intervals(df, window=driven)
        ],
        "lifted_off": scan_metrics.lifted_off(df),
        "scan_window_s": [float(t[window][0]), float(t[window][-1])]
        if window.any()
        else None,
        "campaign_metrics": campaign,
        # What stopped the scan: a stuck channel, "all" (a dead sensor), or
        # null (the watchdog did not).
        "watchdog_channel": result.watchdog_cause or None,
    }


def scan_human_summary(out: dict, scenario) -> str:
    """The scan's result in words (what prints without --json)."""
    c = out["campaign_metrics"]
    window = out["scan_window_s"]
    online = scenario.stiffness_source == "online"
    end = float(scenario.trajectory.end_time_s)
    lines = [
        f"{out['scenario']} ({out['controller']}"
        + (" online" if online else "")
        + f"): {out['duration_s']:.2f} s "
        f"simulated at {out['rtf']:.2f}x real time",
        f"force on the patient (tissue force; the campaign's peak_force_N): peak "
        f"{fmt_number(c['peak_force_N'])} N, p99 {fmt_number(c['p99_force_N'])} N, "
        f"{fmt_number(c['time_above_limit_s'], '.2f')} s above {c['force_limit_N']:g} N "
        f"({c['force_limit_source']})",
        "sensor force ("
        + (
            "the sensor's reading before the scenario's sensor faults"
            if scenario.variations.sensor_faults.active
            else "with its noise"
        )
        + f"; force_peak_N): peak {fmt_number(out['force_peak_N'])} N",
    ]
    if window is None:
        lines.append(
            "no scan window (the probe did not hold its scan height in contact "
            "after first contact + 1 s"
            + (
                f"; the trajectory runs to {end:.1f} s: simulate longer"
                if out["duration_s"] < end
                else ""
            )
            + "): force range and force RMSE n/a"
        )
    else:
        lo, hi = out["force_range_N"]
        rmse = (
            "no force reference (CS)"
            if out["controller"] == "cs"
            else "RMSE against the reference"
            + (" (built on the online estimates)" if online else "")
            + f" {fmt_number(out['force_rmse_N'])} N"
        )
        lines.append(
            f"scan window {window[0]:.2f}-{window[1]:.2f} s: sensor force "
            f"{fmt_number(lo, '.2f')}-{fmt_number(hi, '.2f')} N, {rmse}"
        )
    losses = out["contact_loss_s"]
    if losses:
        spans = ", ".join(f"{a:.2f}-{b:.2f} s" for a, b in losses)
        lines.append(
            f"contact losses: {len(losses)} ({sum(b - a for a, b in losses):.2f} s: "
            f"{spans})"
        )
    else:
        lines.append("contact losses: none")
    cause = out.get("watchdog_channel")
    if cause is not None:
        what = (
            "the force sensor went dead (no new reading on any channel)"
            if cause == "all"
            else f"the {cause} force channel stuck"
        )
        lines.append(
            f"sensor watchdog: {what}; the scan stopped at "
            f"{c['watchdog_trip_s']:.3f} s and the probe lifted away (contact "
            "losses are counted up to then)"
        )
    vs = math.isfinite(c["tank_floor_J"])  # The VS controllers: a tank and a QP.
    parts = [
        f"tank minimum {fmt_number(out['tank_min_J'])} J (floor {c['tank_floor_J']:g} "
        f"J); {c['qp_failures']} failed QP solves"
        if vs
        else f"no energy tank or stiffness QP ({out['controller']})"
    ]
    if c["input_faults"]:
        parts.append(
            f"{c['input_faults']} ticks "
            + (
                "skipped the QP on a non-finite sensor reading (stiffness held at "
                "K_min)"
                if vs
                else "on a non-finite sensor reading"
            )
        )
    if not out["force_peak_N"] > CONTACT_THRESHOLD_N:
        parts.append("never in contact")
    else:
        parts.append(f"lifted off at the end: {'yes' if out['lifted_off'] else 'no'}")
    lines.append("; ".join(parts))
    for key, what in (("log", "log"), ("bag", "bag")):
        if key in out:
            lines.append(f"{what} written to {out[key]}")
    return "\n".join(lines)


__all__ = [
    "SCAN_DESCRIPTION",
    "campaign_force_limit",
    "scan_human_summary",
    "scan_metrics_dict",
]
