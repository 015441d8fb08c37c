"""Scenarios of the real scan logs: controller, target and FDCC gains identified."""

from dataclasses import replace

import pytest

from vic_drake.analysis.identification import (
    estimate_force_loop_gain,
    estimate_tissue_friction,
)
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.experiments.real_logs import (
    FZI_DEFAULT_FDCC_Z_GAINS,
    MODEL_LOOP_GAIN_PER_KP,
    PAPER_FDCC_Z_GAINS,
    detect_controller,
    fit_target_profile,
    identify_fdcc_z_gains,
    scenario_from_real_log,
    with_z_gains,
)
from vic_drake.experiments.scan_diagram import load_scenario_phantom
from vic_drake.experiments.scan_run import run_scan


@pytest.mark.realdata
def test_real_log_scenarios(data_dir):
    from vic_drake.realdata import read_bag

    exp = data_dir / "experiments"
    vf = read_bag(exp / "test_nardi_matForce_lowR")
    cf = read_bag(exp / "test_tracking5")
    assert detect_controller(vf) == "vs-vf" and detect_controller(cf) == "vs-cf"
    s = scenario_from_real_log(vf, name="vf")
    ref = s.controller.reference
    assert ref.controller == "vs-vf" and "vs-vf (identified" in s.description
    assert s.controller.qp.r_weight == [1e-5] * 3
    assert ref.eps_d_m == pytest.approx(0.008) and ref.force_min_z_N == -9.0
    assert s.phantom.kind == "measured" and s.trajectory.waypoints
    assert s.controller.tank.initial_energy_J == pytest.approx(0.5, abs=0.01)
    s = scenario_from_real_log(cf, name="cf", r_weight=0.5)
    assert s.controller.reference.force_ref_N == pytest.approx(7.0)
    assert s.controller.qp.r_weight == [0.5] * 3
    assert "given r_weight = 0.5" in s.description
    profile = fit_target_profile(cf)
    assert profile.scan_speed_m_per_s == pytest.approx(0.01, rel=1e-3)
    assert profile.target_z_m == pytest.approx(0.085, abs=1e-4)
    cs = read_bag(exp / "test_compliance_control400")
    # No name carries the controller: a neutral one gives the same scenario.
    s = scenario_from_real_log(cs, name="mystery_log")
    assert s.controller.reference.controller == "cs"
    k = s.controller.reference.constant_stiffness_N_per_m
    assert k == [k[2]] * 3 and k[2] == pytest.approx(400.0, rel=0.1)
    assert "cs (identified" in s.description
    assert (
        s.trajectory.scan_speed_m_per_s == 0.01 and s.trajectory.liftoff_height_m == 0
    )
    s = scenario_from_real_log(cs, name="x", controller="cs", stiffness_N_per_m=400.0)
    assert s.controller.reference.constant_stiffness_N_per_m == [400.0] * 3
    assert "cs (given)" in s.description
    cf9 = read_bag(exp / "test_force_control")
    s = scenario_from_real_log(cf9, name="y", controller="cf")
    assert s.controller.reference.force_ref_N == pytest.approx(7.0, rel=0.05)
    with pytest.raises(VicDrakeError, match="cs or cf"):
        scenario_from_real_log(cs, name="x", controller="vs-vf")
    short = cs.iloc[:200].copy()
    short.attrs.update(cs.attrs)
    with pytest.raises(VicDrakeError, match="--controller cs"):
        scenario_from_real_log(short, name="short")


@pytest.mark.parametrize("gains", [FZI_DEFAULT_FDCC_Z_GAINS, PAPER_FDCC_Z_GAINS])
def test_identification_recovers_the_station(gains):
    """The identifications run on the real logs, run on a simulated CF scan,
    give back the station's settings: its force loop gain is
    MODEL_LOOP_GAIN_PER_KP k_p (the constant the real logs' FDCC gains are
    scored with), and its tissue force the normal tilt and friction set."""
    s = synthetic_scenario("cf")
    s = replace(s, fdcc=with_z_gains(s.fdcc, *gains))
    df = run_scan(s, duration_s=8.0).df
    est = estimate_force_loop_gain(df[df["t_s"] > 3.0])
    assert est["r2"] > 0.6
    assert est["gain_m_per_s_per_N"] / gains[0] == pytest.approx(
        MODEL_LOOP_GAIN_PER_KP, rel=0.25
    )
    contact = estimate_tissue_friction(
        df,
        load_scenario_phantom(s),
        slip_speed_m_per_s=s.station.tissue_slip_speed_m_per_s,
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
    from vic_drake.analysis.columns import real_to_canonical
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
            real,
            stiffness_z_N_per_m=k_z,
            force_ref_N=f_ref,
            fallback=PAPER_FDCC_Z_GAINS,
        )
        assert got["identified"] and got["r2"] > 0.9, name
        assert got["gain_m_per_s_per_N"] == pytest.approx(2.0e-3, rel=0.1), name
        assert got["gains"] == FZI_DEFAULT_FDCC_Z_GAINS, name
        s = scenario_from_real_log(real, name=name)
        assert (s.fdcc.p_gains[2], s.fdcc.d_gains[2]) == FZI_DEFAULT_FDCC_Z_GAINS
    s = scenario_from_real_log(real, name=name, fdcc_z_gains=PAPER_FDCC_Z_GAINS)
    assert s.fdcc.p_gains[2] == PAPER_FDCC_Z_GAINS[0]


def test_a_setting_the_controller_does_not_have_is_refused():
    from vic_drake.experiments.real_logs import check_settings_apply

    check_settings_apply("cs", False, 400.0, None, None)
    check_settings_apply("vs-cf", True, None, 7.0, 0.1)
    check_settings_apply("vs-vf", False, None, None, 1e-5)
    with pytest.raises(VicDrakeError) as exc:
        check_settings_apply("vs-cf", False, 400.0, None, None)
    assert str(exc.value) == (
        "--stiffness applies to CS; this log was identified as vs-cf (pass "
        "--controller cs to run that instead, or drop --stiffness)"
    )
    with pytest.raises(VicDrakeError, match="--force applies to CF and VS-CF, not"):
        check_settings_apply("cs", True, None, 7.0, None)
    with pytest.raises(VicDrakeError, match="--R applies to VS-CF and VS-VF"):
        check_settings_apply("cf", False, None, None, 0.1)
