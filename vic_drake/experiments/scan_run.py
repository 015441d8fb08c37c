"""Simulating a scan: :func:`run_scan` and its :class:`ScanResult`.

:func:`run_scan` builds the scenario's diagram
(:func:`~vic_drake.experiments.scan_diagram.MakeScanDiagram`), simulates it
and returns the logs as a DataFrame of the canonical columns
(:data:`vic_drake.analysis.columns.CANONICAL_COLUMNS`).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import time
import warnings
from dataclasses import dataclass

import pandas as pd
from pydrake.common import RandomGenerator
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator

from vic_drake.analysis.claims import ScanLimits
from vic_drake.control.watchdog import STUCK_CHANNEL, TRIP_CAUSES, TRIP_TIME
from vic_drake.errors import VicDrakeError, VicDrakeWarning
from vic_drake.experiments.rig_log import rig_frame
from vic_drake.experiments.scan_diagram import (
    MakeScanDiagram,
    initial_joint_positions,
    load_scenario_phantom,
    set_initial_state,
)
from vic_drake.experiments.scan_logs import logs_to_frame
from vic_drake.scenario import Scenario
from vic_drake.station.ik import solve_tip_ik

#: How far the target's path may pass the phantom's footprint before
#: :func:`run_scan` warns, m (the shipped scans end 5 mm past the measured
#: map's edge).
PATH_OUTSIDE_TOLERANCE_M = 0.01


def path_outside_phantom(scenario: Scenario, phantom) -> str | None:
    """What the target's (x, y) path does past the phantom's footprint
    (``phantom.bounds``, moved by ``station.phantom_offset_m``), beyond
    :data:`PATH_OUTSIDE_TOLERANCE_M`; None if it stays on it.

    Past the footprint a phantom holds its edge's surface, kappa and lambda,
    so a scan there scores tissue that was never measured.
    """
    traj = scenario.trajectory
    if traj.waypoints:
        xs = [float(r[1]) for r in traj.waypoints]
        ys = [float(r[2]) for r in traj.waypoints]
    else:
        xs, ys = [float(traj.start_x_m), float(traj.end_x_m)], [float(traj.y_m)]
    ox, oy = (float(v) for v in scenario.station.phantom_offset_m[:2])
    x0, x1, y0, y1 = phantom.bounds
    x0, x1, y0, y1 = x0 + ox, x1 + ox, y0 + oy, y1 + oy
    past = {
        "x": max(x0 - min(xs), max(xs) - x1),
        "y": max(y0 - min(ys), max(ys) - y1),
    }
    far = {axis: d for axis, d in past.items() if d > PATH_OUTSIDE_TOLERANCE_M}
    if not far:
        return None
    parts = ", ".join(f"{1e3 * d:.0f} mm in {axis}" for axis, d in far.items())
    return (
        f"{scenario.name}: the target's path passes the phantom's footprint by "
        f"{parts} (x {x0:.4f} to {x1:.4f} m, y {y0:.4f} to {y1:.4f} m); past it "
        "the phantom holds its edge's surface, kappa and lambda"
    )


def path_out_of_reach(scenario: Scenario) -> str | None:
    """Where the target's path leaves the arm's reach (probe down), or None.

    The start is checked when the run is built (its IK); this checks the
    rest of the path at a few points: the scan's ends and its lift (or,
    for a waypoint path, five rows spread over it), about 4 ms each. Past
    its reach the arm stops short, and the run scores a scan it did not do.
    """
    traj = scenario.trajectory
    if traj.waypoints:
        rows = list(traj.waypoints)
        picks = sorted({round(i * (len(rows) - 1) / 4) for i in range(5)})
        points = [tuple(float(v) for v in rows[i][1:4]) for i in picks]
    else:
        z = float(traj.target_z_m)
        points = [
            (float(traj.start_x_m), float(traj.y_m), z),
            (float(traj.end_x_m), float(traj.y_m), z),
        ]
        if traj.liftoff_height_m > 0:
            points.append((points[1][0], points[1][1], z + traj.liftoff_height_m))
    for point in points:
        try:
            solve_tip_ik(point, params=scenario.station)
        except VicDrakeError:
            shown = ", ".join(f"{v:.3f}" for v in point)
            return (
                f"{scenario.name}: the target's path leaves the arm's reach at "
                f"({shown}) m (no joint configuration puts the probe there "
                "pointing down): the arm stops short, and the run's figures are "
                "not those of the scan asked for"
            )
    return None


@dataclass
class ScanResult:
    """A simulated scan.

    Attributes:
        df: canonical scan DataFrame (see vic_drake.analysis.columns.CANONICAL_COLUMNS;
            with a lateral breathing part, then ``phantom_x_m``, ``phantom_y_m``).
        scenario: the scenario as it ran (a copy, taken when the run
            started; a ``duration_s`` given to :func:`run_scan` is ``sim_s``).
        wall_s: wall-clock time of the simulation (excluding building), s.
        sim_s: simulated time, s.
        rtf: real-time factor, sim_s / wall_s (> 1: faster than real time).
        build_s: wall-clock time spent building the diagram, s.
        cpu_s: CPU time of this process during the simulation, s (on a
            loaded machine sim_s / cpu_s is the real-time factor the run
            would have with a core to itself).
        rig: the signals only a rig log holds, sampled with ``df``
            (:data:`vic_drake.analysis.rig_layout.RIG_SIGNALS`; ``attrs``
            "beta": the phantom's exponent); see
            :func:`vic_drake.experiments.rig_log.rig_log_rows`.
        watchdog_trip_s: when the force sensor's watchdog tripped and the
            probe began to lift away, s (NaN: it did not, or it is off).
        watchdog_channel: what tripped it: the stuck force channel (0, 1,
            2 for x, y, z), :data:`~vic_drake.control.watchdog.DEAD_SENSOR`
            (3: the whole reading froze), or -1 if nothing did.
    """

    df: pd.DataFrame
    scenario: Scenario
    wall_s: float
    sim_s: float
    rtf: float
    build_s: float = 0.0
    cpu_s: float = float("nan")
    rig: pd.DataFrame | None = None
    watchdog_trip_s: float = math.nan
    watchdog_channel: int = -1

    @property
    def watchdog_cause(self) -> str:
        """What stopped the scan: "x", "y" or "z" (a stuck channel), "all"
        (a dead sensor), or "" (the watchdog did not)."""
        return TRIP_CAUSES[self.watchdog_channel] if self.watchdog_channel >= 0 else ""


def run_scan(
    scenario: Scenario,
    *,
    phantom=None,
    duration_s: float | None = None,
    meshcat=None,
    progress=None,
    data_dir=None,
    controller_phantom=None,
) -> ScanResult:
    """Simulates a scenario.

    Args:
        scenario: the run.
        phantom: the tissue (default: loaded from the scenario).
        duration_s: simulated time, s (default: scenario.total_duration_s).
        meshcat: optional Meshcat.
        progress: optional callable(str) receiving progress lines.
        data_dir: data folder for the measured map.
        controller_phantom: the map the controller reads (default: the
            tissue; see :func:`MakeScanDiagram`).

    Returns:
        ScanResult with the canonical DataFrame, wall time and real-time factor.
    """
    if not isinstance(scenario, Scenario):
        raise VicDrakeError(f"run_scan needs a Scenario; got {type(scenario).__name__}")
    # A scenario changed in code since it was loaded is checked again here
    # (the loader checks a file's).
    scenario.validate()
    duration = scenario.total_duration_s if duration_s is None else float(duration_s)
    if not duration > 0:
        raise VicDrakeError(f"duration_s must be > 0; got {duration_s!r}")
    # The result keeps the scenario as it ran: the caller's object may change
    # after (a sweep that edits one scenario). A duration given here is not
    # written into it (it is the result's sim_s): the scenario's own length
    # sets its breathing's cycles, so the copy replays the same run.
    scenario = copy.deepcopy(scenario)
    t_build = time.perf_counter()
    if phantom is None:
        phantom = load_scenario_phantom(scenario, data_dir=data_dir)
    for problem in (
        path_outside_phantom(scenario, phantom),
        path_out_of_reach(scenario),
    ):
        if problem:
            warnings.warn(problem, VicDrakeWarning, stacklevel=2)
    diagram, logs = MakeScanDiagram(
        scenario,
        phantom=phantom,
        meshcat=meshcat,
        data_dir=data_dir,
        controller_phantom=controller_phantom,
    )
    simulator = Simulator(diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    context = simulator.get_mutable_context()
    diagram.SetRandomContext(context, RandomGenerator(scenario.seed))
    set_initial_state(diagram, context, initial_joint_positions(scenario))
    simulator.Initialize()
    build_s = time.perf_counter() - t_build
    if progress:
        progress(f"{scenario.name}: simulating {duration:.2f} s")
    t0, c0 = time.perf_counter(), time.process_time()
    chunk = max(1.0, duration / 10)
    t = 0.0
    while t < duration - 1e-12:
        t = min(duration, t + chunk)
        simulator.AdvanceTo(t)
        if progress:
            elapsed = time.perf_counter() - t0
            progress(
                f"{scenario.name}: t = {t:.1f} / {duration:.1f} s ({elapsed:.1f} s wall)"
            )
    wall = time.perf_counter() - t0
    cpu = time.process_time() - c0
    df = logs_to_frame(logs, context)
    fdcc = diagram.GetSubsystemByName("fdcc")
    watch = fdcc.watchdog_state(fdcc.GetMyContextFromRoot(context))
    trip_s, channel = float(watch[TRIP_TIME]), int(watch[STUCK_CHANNEL])
    # The controller travels with the log: CS has no force reference and
    # neither CS nor CF a tank (scan_metrics reads it).
    df.attrs.update(
        source="sim",
        scenario=scenario.name,
        controller=scenario.controller.reference.controller,
        scan_limits=dataclasses.asdict(ScanLimits.from_controller(scenario.controller)),
    )
    rig = rig_frame(logs, context)
    rig.attrs["beta"] = float(phantom.beta)
    return ScanResult(
        df=df,
        scenario=scenario,
        wall_s=wall,
        sim_s=duration,
        rtf=duration / wall if wall > 0 else float("inf"),
        build_s=build_s,
        cpu_s=cpu,
        rig=rig,
        watchdog_trip_s=trip_s,
        watchdog_channel=channel,
    )


__all__ = [
    "PATH_OUTSIDE_TOLERANCE_M",
    "ScanResult",
    "path_out_of_reach",
    "path_outside_phantom",
    "run_scan",
]
