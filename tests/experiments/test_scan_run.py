"""Simulating a scan: the canonical frame, figures from it, bad input, a full scan."""

import numpy as np
import pytest

from vic_drake.analysis.columns import CANONICAL_COLUMNS
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.experiments.scan_diagram import MakeScanDiagram
from vic_drake.experiments.scan_run import run_scan


def test_short_run_returns_the_canonical_frame():
    scenario = synthetic_scenario("vs-vf")
    result = run_scan(scenario, duration_s=0.2)
    df = result.df
    assert tuple(df.columns) == CANONICAL_COLUMNS
    assert df["t_s"].iloc[-1] == pytest.approx(0.2, abs=2.5e-3)
    assert np.all(
        np.isfinite(df[["x_m", "z_m", "force_sensor_z_N", "stiffness_z_N_per_m"]])
    )
    # The probe starts at rest where the IK put it: at the target, above the surface.
    np.testing.assert_allclose(df[["x_m", "y_m"]].iloc[0], [0.036, -0.36], atol=1e-3)
    assert df["z_m"].iloc[0] == pytest.approx(0.12, abs=1e-3)
    assert df["penetration_m"].iloc[0] < 0  # Not touching yet.
    assert result.rtf > 0 and result.wall_s > 0


def test_scan_figures_draw_sim_and_real(tmp_path):
    from vic_drake.reproduce.plots.scans import plot_comparison, plot_fig6, plot_fig7

    df = run_scan(synthetic_scenario("vs-cf"), duration_s=0.1).df
    fig = plot_fig6(
        {"vs-cf": df, "vs-vf": df}, {"vs-vf": df}, save_path=tmp_path / "f6.png"
    )
    # In 0.1 s, before contact, K_z sits at K_min: a row without information
    # is not drawn (force, penetration, tank remain).
    assert len(fig.axes) == 3 * 2 and (tmp_path / "f6.png").stat().st_size > 0
    fig = plot_fig7({"vs-vf": df, "cs": df, "cf": df})
    assert len(fig.axes) == 2 * 3  # force and height; K_z flat in all three
    fig = plot_comparison(df, df)
    assert len(fig.axes) == 3
    with pytest.raises(VicDrakeError):
        plot_fig6({})


def test_run_scan_rejects_bad_input():
    with pytest.raises(VicDrakeError, match="duration_s"):
        run_scan(synthetic_scenario("cs"), duration_s=-1.0)
    with pytest.raises(VicDrakeError, match="Scenario"):
        MakeScanDiagram({"name": "not a scenario"})
    with pytest.raises(VicDrakeError, match="controller"):
        synthetic_scenario("pid")
    with pytest.raises(VicDrakeError, match="run_scan needs a Scenario; got dict"):
        run_scan({"name": "not a scenario"})


@pytest.mark.parametrize(
    "part, field, value, message",
    [
        ("trajectory", "scan_speed_m_per_s", -0.01, r"scan_speed_m_per_s must be > 0"),
        ("", "seed", -3, r"Scenario\.seed must be an integer >= 0"),
        # Lengths, speeds and forces typed in other units (a first-contact
        # review: 48 for a 48 mm lift ran, and reported 8,327 N).
        (
            "trajectory",
            "liftoff_height_m",
            48.0,
            r"liftoff_height_m is in metres and must be at most 0.2 m; got 48.0",
        ),
        (
            "trajectory",
            "scan_speed_m_per_s",
            10.0,
            r"scan_speed_m_per_s is in m/s and must be at most 0.1 m/s",
        ),
        (
            "station",
            "phantom_offset_m",
            [0.0, 0.0, 10.0],
            r"phantom_offset_m is in metres, each at most 0.1 m in size",
        ),
        (
            "controller.reference",
            "force_ref_N",
            700.0,
            r"force_ref_N must be at most 50 N; got 700.0",
        ),
        (
            "controller.reference",
            "force_min_z_N",
            -700.0,
            r"force_min_z_N must be >= -50 N",
        ),
        # A number as text would stay text, to fail inside the simulation.
        (
            "controller.reference",
            "force_ref_N",
            "5",
            r"force_ref_N must be a number; got '5' \(a str\)",
        ),
        # A misspelt field set in code would be kept and never read.
        (
            "controller.reference",
            "force_ref",
            5.0,
            r"Scenario\.controller\.reference has no field 'force_ref' \(set in "
            r"code, it would be ignored\); did you mean force_ref_N",
        ),
        ("", "controler", None, r"Scenario has no field 'controler'"),
    ],
)
def test_a_scenario_changed_in_code_is_checked_before_it_runs(
    part, field, value, message
):
    scenario = synthetic_scenario("cf")
    owner = scenario
    for name in part.split(".") if part else ():
        owner = getattr(owner, name)
    setattr(owner, field, value)
    with pytest.raises(VicDrakeError, match=message):
        run_scan(scenario, duration_s=0.1)
    with pytest.raises(VicDrakeError, match=message):
        MakeScanDiagram(scenario)


def test_the_result_keeps_the_scenario_as_it_ran():
    """A sweep that edits one scenario between runs leaves each result with
    the values it ran with. A duration given to run_scan is the result's
    sim_s, not written into the scenario, whose own length sets its
    breathing's cycles."""
    scenario = synthetic_scenario("cf")
    result = run_scan(scenario, duration_s=0.1)
    scenario.controller.reference.force_ref_N = 5.0
    assert result.scenario.controller.reference.force_ref_N == 7.0
    assert result.scenario.duration_s is None and result.sim_s == 0.1
    # The log carries its controller's limits: CF has no tank, does not aim
    # at eps_d.
    limits = result.df.attrs["scan_limits"]
    assert limits["has_tank"] is False and limits["targets_penetration"] is False


@pytest.mark.slow
def test_full_vs_vf_nominal_scan_tracks_and_lifts_off():
    """The whole synthetic VS-VF scan (~24 s simulated)."""
    from vic_drake.analysis import scan_metrics as metrics

    result = run_scan(synthetic_scenario("vs-vf"))
    df = result.df
    assert metrics.lifted_off(df)
    assert metrics.tank_min_J(df) >= 0.4 - 1e-6
    assert metrics.peak_force_N(df) < 15.0


def test_the_phantom_starts_at_rest_where_its_motion_starts():
    """A lift that starts off zero (a real log's replayed motion) is where the
    phantom starts, at rest: it is not driven up into the probe at t = 0."""
    from vic_drake.scenario import DisturbanceConfig

    scenario = synthetic_scenario("cs")
    scenario.disturbance = DisturbanceConfig(table=[[0.0, 0.004], [1.0, 0.004]])
    df = run_scan(scenario, duration_s=0.05).df
    np.testing.assert_allclose(df["phantom_lift_m"], 0.004, atol=1e-7)


@pytest.mark.realdata
def test_a_disturbed_real_logs_scenario_starts_without_an_impact(data_dir):
    """diagrams/real_test_force_control_dist.yaml starts in contact with its
    phantom lifted 6.1 mm; the log starts at 5.7 N. With the phantom started
    at zero lift its servo drove it into the probe: 21.8 N at 6 ms."""
    from vic_drake.experiments import load_diagram

    scenario = load_diagram("real_test_force_control_dist")
    df = run_scan(scenario, duration_s=0.5, data_dir=data_dir).df
    assert df["force_sensor_z_N"].abs().max() < 8.0


def test_a_path_past_the_phantom_is_warned():
    """Past its footprint a phantom holds its edge's values: tissue nobody
    measured. run_scan says so; the shipped paths stay on it."""
    import io

    from vic_drake.cli import _show_warning
    from vic_drake.errors import VicDrakeWarning
    from vic_drake.experiments.scan_run import path_outside_phantom
    from vic_drake.tissue import SyntheticChestPhantom

    phantom = SyntheticChestPhantom()
    assert path_outside_phantom(synthetic_scenario("cf"), phantom) is None
    scenario = synthetic_scenario("cf")
    scenario.trajectory.end_x_m = scenario.trajectory.end_x_m - 0.08
    message = path_outside_phantom(scenario, phantom)
    assert "passes the phantom's footprint by 19 mm in x" in message
    with pytest.warns(VicDrakeWarning, match="passes the phantom's footprint"):
        run_scan(scenario, phantom=phantom, duration_s=0.02)
    # The phantom moved by the station's offset moves its footprint: the
    # shipped path (x from 0.036 to -0.164 m; the chest from 0.105 to -0.225)
    # leaves it when the chest moves 9 cm towards +x.
    shipped = synthetic_scenario("cf")
    shipped.station.phantom_offset_m = [0.09, 0.0, 0.0]
    assert "by 29 mm in x" in path_outside_phantom(shipped, phantom)
    # The command line prints it as one line.
    out = io.StringIO()
    _show_warning(message, VicDrakeWarning, "x.py", 1, file=out)
    assert out.getvalue() == f"vic-drake: warning: {message}\n"


def test_a_path_past_the_arms_reach_is_warned():
    """The start's IK is checked when the run is built; a scan end the arm
    cannot reach (a 72 s run stuck at x = -0.47 m in the review) is warned."""
    from vic_drake.errors import VicDrakeWarning
    from vic_drake.experiments.scan_run import path_out_of_reach

    assert path_out_of_reach(synthetic_scenario("cf")) is None
    scenario = synthetic_scenario("cf")
    scenario.trajectory.end_x_m = -0.64
    message = path_out_of_reach(scenario)
    assert "leaves the arm's reach at (-0.640, -0.360, 0.085) m" in message
    with pytest.warns(VicDrakeWarning) as record:
        run_scan(scenario, duration_s=0.02)
    said = [str(w.message) for w in record]
    # So far out, it is also past the chest: both are said.
    assert any("leaves the arm's reach" in m for m in said)
    assert any("passes the phantom's footprint by 415 mm" in m for m in said)
    # A waypoint path is checked along its rows.
    scenario = synthetic_scenario("cf")
    scenario.trajectory.waypoints = [
        [0.0, 0.036, -0.36, 0.12],
        [5.0, -0.2, -0.36, 0.09],
        [10.0, -0.7, -0.36, 0.09],
    ]
    assert "(-0.700, -0.360, 0.090)" in path_out_of_reach(scenario)
