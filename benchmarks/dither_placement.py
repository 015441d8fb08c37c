"""Where does a dither reach the tissue: the target's height or the desired
penetration?

Runs the VS-VF nominal scan on the synthetic chest with its true map for
``--duration`` seconds twice, each with a 0.3 mm, 3 Hz dither:

- "target z": added to the target's height z_d (a dense waypoint table);
- "eps_d": the references' desired penetration
  (``ReferenceParams.penetration_dither_m``),

and prints the 3 Hz amplitude of the target height, tip height, sensor force
and K_z over the scan (4.5 s to the end; a cubic trend removed) and the
lowest tank energy.

    python benchmarks/dither_placement.py [--duration 9]
"""

from __future__ import annotations

import argparse
import copy

import numpy as np

AMPLITUDE_M, HZ = 3e-4, 3.0


def _amplitude(t, x, hz):
    X = np.column_stack(
        [t**j for j in range(4)]
        + [np.cos(2 * np.pi * hz * t), np.sin(2 * np.pi * hz * t)]
    )
    c = np.linalg.lstsq(X, x, rcond=None)[0]
    return float(np.hypot(c[4], c[5]))


def main() -> None:
    from vic_drake.experiments.scan_diagram import load_scenario_phantom
    from vic_drake.experiments.scan_run import run_scan
    from vic_drake.scenario import Scenario
    from vic_drake.systems.trajectory import target_knots

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=9.0)
    args = parser.parse_args()
    base = Scenario()
    phantom = load_scenario_phantom(base)

    target = copy.deepcopy(base)
    t, p = target_knots(base.trajectory)
    tt = np.arange(0.0, t[-1], 0.002)
    rows = np.vstack([tt] + [np.interp(tt, t, p[i]) for i in range(3)]).T
    rows[:, 3] += np.where(tt > 3.5, AMPLITUDE_M * np.sin(2 * np.pi * HZ * tt), 0.0)
    target.trajectory.waypoints = rows.tolist()
    target.trajectory.initial_tip_z_m = base.trajectory.approach_z_m

    eps_d = copy.deepcopy(base)
    eps_d.controller.reference.penetration_dither_m = AMPLITUDE_M
    eps_d.controller.reference.penetration_dither_hz = HZ

    print(
        "| dither on | z_d amp mm | tip z amp mm | force amp N | K_z amp N/m | tank min J |"
    )
    print("|---|---|---|---|---|---|")
    for name, scenario in (("target z", target), ("eps_d", eps_d)):
        df = run_scan(scenario.validate(), phantom=phantom, duration_s=args.duration).df
        t = df["t_s"].to_numpy(float)
        sel = t > 4.5
        amp = {
            c: _amplitude(t[sel], df[c].to_numpy(float)[sel], HZ)
            for c in ("z_d_m", "z_m", "force_sensor_z_N", "stiffness_z_N_per_m")
        }
        print(
            f"| {name} | {amp['z_d_m'] * 1e3:.3f} | {amp['z_m'] * 1e3:.3f} | "
            f"{amp['force_sensor_z_N']:.3f} | {amp['stiffness_z_N_per_m']:.1f} | "
            f"{df['tank_energy_J'].min():.3f} |"
        )


if __name__ == "__main__":
    main()
