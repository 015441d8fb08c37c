"""Scenario tree: YAML round trip through Drake's typed loader, validation,
and the reference sources built from it."""

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder

from vic_drake.errors import VicDrakeError
from vic_drake.scenario import (
    DisturbanceConfig,
    PhantomLift,
    Scenario,
    TrajectoryConfig,
    dumps_scenario,
    load_scenario,
    loads_scenario,
    save_scenario,
)
from vic_drake.systems.trajectory import (
    PhantomLiftSource,
    TargetTrajectorySource,
    phantom_lift_m,
    target_knots,
)


def test_default_scenario_round_trips_through_yaml(tmp_path):
    scenario = Scenario(
        disturbance=DisturbanceConfig(lifts=[PhantomLift(start_s=3.0, height_m=0.01)]),
        trajectory=TrajectoryConfig(initial_tip_z_m=0.11),
        duration_s=5.0,
    )
    path = save_scenario(scenario, tmp_path / "s.yaml")
    loaded = load_scenario(path)
    assert loaded == scenario
    # Nested parameter classes of other areas come back as their own types.
    assert type(loaded.station) is type(scenario.station)
    assert type(loaded.controller.reference) is type(scenario.controller.reference)
    assert dumps_scenario(loaded) == path.read_text()


def test_partial_yaml_keeps_defaults_and_validates_nested_values():
    s = loads_scenario("controller: {reference: {controller: cs}}\nseed: 3\n")
    assert s.controller.reference.controller == "cs" and s.seed == 3
    assert s.trajectory == TrajectoryConfig()


@pytest.mark.parametrize(
    "text, match",
    [
        ("controller: {reference: {controller: pid}}", "controller must be one of"),
        ("trajectory: {target_z: 0.08}", r"trajectory\.target_z is unknown"),
        ("trajectory: {target_z_m: deep}", r"trajectory\.target_z_m must be a float"),
        ("trajectory: {approach_z_m: 0.05}", "approach_z_m"),
        ("disturbance: {table: [[0, 0], [0, 0.01]]}", "times must increase"),
        ("disturbance: {lifts: [{rise_s: 0}]}", r"PhantomLift\.rise_s"),
        ("phantom: {kind: cadaver}", r"PhantomConfig\.kind"),
        ("logging: {period_s: 0}", r"LoggingConfig\.period_s"),
        ("seed: -2", r"Scenario\.seed"),
    ],
)
def test_bad_yaml_names_the_field(text, match):
    with pytest.raises(VicDrakeError, match=match):
        loads_scenario(text)


def test_bad_file_names_the_file(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("duration_s: -1\n")
    with pytest.raises(VicDrakeError, match=r"bad\.yaml.*duration_s"):
        load_scenario(path)
    with pytest.raises(VicDrakeError, match="does not exist"):
        load_scenario(tmp_path / "missing.yaml")


def test_parametric_target_matches_the_real_scans_profile():
    config = TrajectoryConfig()  # 0.108 -> 0.085 at 1 cm/s, 20 cm along -x, lift-off.
    t, p = target_knots(config)
    np.testing.assert_allclose(t[:3], [0.0, 2.3, 22.3])
    np.testing.assert_allclose(p[:, 1], [0.036, -0.36, 0.085])
    np.testing.assert_allclose(p[:, 2], [-0.164, -0.36, 0.085])
    np.testing.assert_allclose(p[2, -1], 0.085 + 0.048)
    assert config.end_time_s == pytest.approx(22.3)


def _eval_at(system, port, t):
    context = system.CreateDefaultContext()
    context.SetTime(t)
    return port.Eval(context)


def test_target_source_outputs_position_and_velocity():
    source = TargetTrajectorySource(TrajectoryConfig())
    p = _eval_at(source, source.get_target_position_output_port(), 12.3)
    v = _eval_at(source, source.get_target_velocity_output_port(), 12.3)
    np.testing.assert_allclose(p, [0.036 - 0.01 * 10.0, -0.36, 0.085], atol=1e-12)
    np.testing.assert_allclose(v, [-0.01, 0.0, 0.0], atol=1e-12)
    v_end = _eval_at(source, source.get_target_velocity_output_port(), 100.0)
    np.testing.assert_allclose(v_end, 0.0)


def test_waypoint_target_interpolates_the_table():
    config = TrajectoryConfig(
        waypoints=[[0, 0, 0, 0.1], [2, -0.02, 0, 0.1], [3, -0.02, 0, 0.2]]
    )
    source = TargetTrajectorySource(config)
    p = _eval_at(source, source.get_target_position_output_port(), 1.0)
    np.testing.assert_allclose(p, [-0.01, 0.0, 0.1])
    assert config.start_tip_z_m == 0.1 and config.end_time_s == 3.0


def test_phantom_lift_profile_and_source():
    lift = PhantomLift(start_s=1.0, height_m=0.02, rise_s=1.0, hold_s=2.0, fall_s=0.5)
    config = DisturbanceConfig(lifts=[lift])
    z = phantom_lift_m([0.0, 1.5, 2.0, 3.9, 4.25, 5.0], config)
    np.testing.assert_allclose(z, [0.0, 0.01, 0.02, 0.02, 0.01, 0.0], atol=1e-12)
    table = DisturbanceConfig(table=[[1.0, 0.0], [2.0, 0.01]])
    np.testing.assert_allclose(
        phantom_lift_m([0.0, 1.5, 9.0], table), [0.0, 0.005, 0.01]
    )
    source = PhantomLiftSource(config)
    builder = DiagramBuilder()
    builder.AddSystem(source)
    assert _eval_at(source, source.get_phantom_lift_output_port(), 1.5)[
        0
    ] == pytest.approx(0.01)
