"""The closed-loop scan diagram: wiring, a short run, and the real-log scenarios."""

from dataclasses import replace

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments import (
    FZI_DEFAULT_FDCC_Z_GAINS,
    LOG_GROUPS,
    MODEL_LOOP_GAIN_PER_KP,
    PAPER_FDCC_Z_GAINS,
    MakeScanDiagram,
    _with_z_gains,
    detect_controller,
    fit_target_profile,
    identify_fdcc_z_gains,
    load_scenario_phantom,
    run_scan,
    scenario_from_real_log,
    synthetic_scenario,
)
from vic_drake.metrics import (
    CANONICAL_COLUMNS,
    estimate_force_loop_gain,
    estimate_tissue_friction,
)


def test_scan_diagram_is_wired_and_logs_every_group():
    diagram, loggers = MakeScanDiagram(synthetic_scenario("vs-vf"))
    assert diagram.get_name() == "scan"
    assert set(loggers) == {name for name, *_ in LOG_GROUPS}
    # Closed loop: no input port is left open.
    assert diagram.num_input_ports() == 0
    for name in (
        "station",
        "variable_impedance_controller",
        "fdcc",
        "target",
        "phantom_lift",
    ):
        diagram.GetSubsystemByName(name)


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
    from vic_drake.plots.scans import plot_comparison, plot_fig6, plot_fig7

    df = run_scan(synthetic_scenario("vs-cf"), duration_s=0.1).df
    fig = plot_fig6(
        {"vs-cf": df, "vs-vf": df}, {"vs-vf": df}, save_path=tmp_path / "f6.png"
    )
    assert len(fig.axes) == 8 and (tmp_path / "f6.png").stat().st_size > 0
    fig = plot_fig7({"vs-vf": df, "cs": df, "cf": df})
    assert len(fig.axes) == 9
    fig = plot_comparison(df, df)
    assert len(fig.axes) == 3
    with pytest.raises(VicDrakeError):
        plot_fig6({})


def test_command_feedback_reads_the_tip_from_the_joint_command():
    from dataclasses import replace

    scenario = replace(synthetic_scenario("vs-vf"), controller_feedback="command")
    diagram, _ = MakeScanDiagram(scenario)
    diagram.GetSubsystemByName("commanded_tip")
    df = run_scan(scenario, duration_s=0.05).df
    # At rest at the start the commanded tip is where the arm is.
    np.testing.assert_allclose(
        df[["x_m", "y_m", "z_m"]].iloc[0], [0.036, -0.36, 0.12], atol=1e-3
    )


def test_run_scan_rejects_bad_input():
    with pytest.raises(VicDrakeError, match="duration_s"):
        run_scan(synthetic_scenario("cs"), duration_s=-1.0)
    with pytest.raises(VicDrakeError, match="Scenario"):
        MakeScanDiagram({"name": "not a scenario"})
    with pytest.raises(VicDrakeError, match="controller"):
        synthetic_scenario("pid")


def test_controller_reads_the_map_with_its_own_lookup():
    from dataclasses import replace

    from vic_drake.experiments import _controller_phantom
    from vic_drake.scenario import PhantomConfig
    from vic_drake.tissue.phantom import GridPhantom

    xs, ys = np.array([0.0, 0.01]), np.array([0.0, 0.01])
    grid = np.array([[1000.0, 2000.0], [3000.0, 4000.0]])
    tissue = GridPhantom(x_m=xs, y_m=ys, z_m=np.zeros((2, 2)), kappa=grid, lam=grid)
    tissue.point_lookup()  # The tissue's (bilinear) fast lookup is cached first.
    scenario = replace(
        synthetic_scenario("vs-vf"), phantom=PhantomConfig(kind="measured")
    )
    ctrl = _controller_phantom(scenario, tissue)
    assert ctrl.point_lookup()(0.004, 0.001)[3] == pytest.approx(1000.0)  # Nearest.
    assert tissue.point_lookup()(0.004, 0.001)[3] == pytest.approx(1900.0)  # Bilinear.


@pytest.mark.realdata
def test_real_log_scenarios(data_dir):
    from vic_drake.realdata import read_bag

    exp = data_dir / "experiments"
    vf = read_bag(exp / "test_nardi_matForce_lowR")
    cf = read_bag(exp / "test_tracking5")
    assert detect_controller(vf) == "vs-vf" and detect_controller(cf) == "vs-cf"
    s = scenario_from_real_log(vf, name="vf")
    assert s.controller.reference.controller == "vs-vf"
    assert s.controller.qp.r_weight == [1e-5] * 3
    assert s.phantom.kind == "measured" and s.trajectory.waypoints
    assert s.controller.tank.initial_energy_J == pytest.approx(0.5, abs=0.01)
    s = scenario_from_real_log(cf, name="cf", r_weight=0.5)
    assert s.controller.reference.force_ref_N == pytest.approx(7.0)
    assert s.controller.qp.r_weight == [0.5] * 3
    profile = fit_target_profile(cf)
    assert profile.scan_speed_m_per_s == pytest.approx(0.01, rel=1e-3)
    assert profile.target_z_m == pytest.approx(0.085, abs=1e-4)
    cs = read_bag(exp / "test_compliance_control400")
    s = scenario_from_real_log(cs, name="test_compliance_control400")
    assert s.controller.reference.controller == "cs"
    assert s.controller.reference.constant_stiffness_N_per_m == [400.0] * 3
    assert (
        s.trajectory.scan_speed_m_per_s == 0.01 and s.trajectory.liftoff_height_m == 0
    )
    with pytest.raises(VicDrakeError, match="--controller"):
        scenario_from_real_log(cs, name="mystery_log")
    with pytest.raises(VicDrakeError, match="cs or cf"):
        scenario_from_real_log(cs, name="x", controller="vs-vf")


@pytest.mark.parametrize("gains", [FZI_DEFAULT_FDCC_Z_GAINS, PAPER_FDCC_Z_GAINS])
def test_identification_recovers_the_station(gains):
    """The identifications run on the real logs, run on a simulated CF scan,
    give back the station's settings: its force loop gain is
    MODEL_LOOP_GAIN_PER_KP k_p (the constant the real logs' FDCC gains are
    scored with), and its tissue force the normal tilt and friction set."""
    s = synthetic_scenario("cf")
    s = replace(s, fdcc=_with_z_gains(s.fdcc, *gains))
    df = run_scan(s, duration_s=8.0).df
    est = estimate_force_loop_gain(df[df["t_s"] > 3.0])
    assert est["r2"] > 0.6
    assert est["gain_m_per_s_per_N"] / gains[0] == pytest.approx(
        MODEL_LOOP_GAIN_PER_KP, rel=0.25
    )
    contact = estimate_tissue_friction(
        df, load_scenario_phantom(s), slip_speed_m_per_s=s.station.tissue_slip_speed_m_per_s
    )
    assert contact["samples"] > 1000
    assert contact["tilt"] == pytest.approx(1.0, abs=0.05)
    assert contact["friction_coefficient"] == pytest.approx(
        s.station.tissue_friction_coefficient, abs=0.02
    )


@pytest.mark.realdata
def test_real_scans_show_normal_tilt_and_friction(data_dir):
    """The VS logs' lateral sensor forces: tilted along the surface normal,
    plus a sliding friction near the station's default coefficient."""
    from vic_drake.metrics import real_to_canonical
    from vic_drake.realdata import read_bag
    from vic_drake.station import StationParams
    from vic_drake.tissue.phantom import load_phantom

    phantom = load_phantom("measured", data_dir=data_dir)
    mu = StationParams().tissue_friction_coefficient
    for name in ("test_tracking5", "test_nardi_matForce_lowR"):
        real = real_to_canonical(read_bag(data_dir / "experiments" / name))
        got = estimate_tissue_friction(real, phantom)
        assert got["r2"] > 0.7, name
        assert 0.75 < got["tilt"] < 1.1, name
        assert got["friction_coefficient"] == pytest.approx(mu, abs=0.06), name


@pytest.mark.realdata
def test_cs_and_cf_logs_ran_with_the_fzi_default_gains(data_dir):
    """Every 9-column baseline log's loop gain points at FZI's default z gains
    (the paper's text gives CF k_p = 0.3; its logs say otherwise)."""
    from vic_drake.realdata import read_bag

    for name, k_z, f_ref in (
        ("test_compliance_control400", 400.0, 0.0),
        ("test_compliance_control400_dist", 400.0, 0.0),
        ("test_force_control", 0.0, 7.0),
        ("test_force_control_dist", 0.0, 7.0),
    ):
        real = read_bag(data_dir / "experiments" / name)
        got = identify_fdcc_z_gains(
            real, stiffness_z_N_per_m=k_z, force_ref_N=f_ref, fallback=PAPER_FDCC_Z_GAINS
        )
        assert got["identified"] and got["r2"] > 0.9, name
        assert got["gain_m_per_s_per_N"] == pytest.approx(2.0e-3, rel=0.1), name
        assert got["gains"] == FZI_DEFAULT_FDCC_Z_GAINS, name
        s = scenario_from_real_log(real, name=name)
        assert (s.fdcc.p_gains[2], s.fdcc.d_gains[2]) == FZI_DEFAULT_FDCC_Z_GAINS
    s = scenario_from_real_log(real, name=name, fdcc_z_gains=PAPER_FDCC_Z_GAINS)
    assert s.fdcc.p_gains[2] == PAPER_FDCC_Z_GAINS[0]


@pytest.mark.slow
def test_full_vs_vf_nominal_scan_tracks_and_lifts_off():
    """The whole synthetic VS-VF scan (~24 s simulated)."""
    from vic_drake import metrics

    result = run_scan(synthetic_scenario("vs-vf"))
    df = result.df
    assert metrics.lifted_off(df)
    assert metrics.tank_min_J(df) >= 0.4 - 1e-6
    assert metrics.peak_force_N(df) < 15.0
