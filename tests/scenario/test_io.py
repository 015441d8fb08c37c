"""Scenario YAML through Drake's typed loader and dumper: round trip, defaults,
and errors that name the field and the bad value."""

import pytest

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


def test_only_changes_dump_round_trips_and_is_short():
    scenario = Scenario(seed=4, duration_s=2.0)
    text = dumps_scenario(scenario, only_changes=True)
    assert text == "seed: 4\nduration_s: 2.0\n"
    assert loads_scenario(text) == scenario


def test_the_watchdog_is_on_by_default_and_round_trips():
    assert Scenario().watchdog.enabled
    scenario = loads_scenario("watchdog: {enabled: false, stuck_window_s: 0.1}\n")
    assert not scenario.watchdog.enabled
    assert scenario.watchdog.stuck_window_s == 0.1
    assert loads_scenario(dumps_scenario(scenario)) == scenario
    scenario = loads_scenario(
        "watchdog: {dead_window_s: 0.1}\n"
        "variations: {sensor_faults: {dead: true, dead_start_s: 2.5}}\n"
    )
    assert scenario.watchdog.dead_window_s == 0.1
    assert scenario.variations.sensor_faults.dead
    assert scenario.variations.sensor_faults.active
    assert loads_scenario(dumps_scenario(scenario)) == scenario


def test_simulator_config_round_trips():
    scenario = Scenario()
    scenario.simulator.target_realtime_rate = 1.0
    loaded = loads_scenario(dumps_scenario(scenario, only_changes=True))
    assert loaded.simulator.target_realtime_rate == 1.0
    assert loaded == scenario


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
        ("simulator: {integration_scheme: magic}", r"simulator\.integration_scheme"),
        ("simulator: {max_step: 0.1}", r"simulator\.max_step is unknown"),
        ("simulator: {start_time: 1.0}", r"simulator\.start_time must be 0"),
        ("watchdog: {stuck_window_s: -1}", r"SensorWatchdogParams\.stuck_window_s"),
        ("watchdog: {enable: false}", r"watchdog\.enable is unknown"),
        ("watchdog: {dead_window_s: 0}", r"SensorWatchdogParams\.dead_window_s"),
        (
            "station: {sensor_period_s: 0.08}",
            r"watchdog\.dead_window_s \(0\.1 s\) must be at least twice "
            r"station\.sensor_period_s \(0\.08 s\)",
        ),
        (
            "controller: {reference: {eps_d_m: 8}}",
            r"eps_d_m is in metres and must be at most 0\.05 m; got 8\.0",
        ),
        (
            "variations: {sensor_faults: {stuck_channel: z}}",
            r"stuck_channel must be an int; got 'z'; allowed: -1 \(none\), 0 \(x\)",
        ),
        (
            "stiffness_source: online\ncontroller: {reference: {controller: cf}}",
            r"stiffness_source 'online' is for the variable-stiffness controllers "
            r"\(vs-cf, vs-vf\).*cf does not read them",
        ),
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


def test_dump_needs_a_scenario():
    with pytest.raises(VicDrakeError, match="needs a Scenario"):
        dumps_scenario(TrajectoryConfig())


def test_another_kind_of_vic_drake_yaml_is_named(tmp_path):
    """A palpation log's settings (written by reproduce) or a campaign spec
    given to the scenario loader is named as such, not as unknown fields."""
    import pandas as pd

    from vic_drake.experiments.campaign_params import CampaignParams
    from vic_drake.paths import PROJECT_ROOT
    from vic_drake.reproduce import ReproduceOptions, RunContext
    from vic_drake.reproduce.context import _write_log

    ctx = RunContext(ReproduceOptions(out_dir=tmp_path))
    config = {"campaign_params": CampaignParams(), "phantom": "synthetic", "seed": 0}
    _write_log(ctx, "palpation_sim_2.5hz", pd.DataFrame({"t_s": [0.0]}), config)
    path = tmp_path / "logs" / "palpation_sim_2.5hz.yaml"
    with pytest.raises(VicDrakeError) as err:
        load_scenario(path)
    msg = str(err.value)
    assert "palpation_sim_2.5hz.yaml" in msg and "not a scan scenario" in msg
    assert "palpation campaign's settings" in msg and "unknown" not in msg
    with pytest.raises(VicDrakeError, match="campaign spec; run it with vic-drake"):
        load_scenario(PROJECT_ROOT / "campaigns" / "smoke.yaml")
    # A scenario with a misspelt field still gets the field error.
    with pytest.raises(VicDrakeError, match="duraton_s is unknown"):
        loads_scenario("duraton_s: 3\n")


def test_a_bare_name_points_to_load_diagram(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(
        VicDrakeError, match=r"use vic_drake\.experiments\.load_diagram"
    ):
        load_scenario("nominal_vs_vf_synthetic")


@pytest.mark.parametrize("text", ["", "  \n", None])
def test_empty_yaml_text_is_named(text):
    with pytest.raises(VicDrakeError, match=r"scenario YAML: the text is empty"):
        loads_scenario(text)
