"""The scenario's variations: defaults off, validation, YAML round trip."""

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.scenario import Scenario, dumps_scenario, loads_scenario
from vic_drake.scenario.variation import (
    BreathingConfig,
    MapErrorConfig,
    PatientConfig,
    PatientMotionConfig,
    SensorFaultConfig,
    VariationConfig,
)


def test_defaults_are_off_and_absent_from_a_diff_dump():
    v = VariationConfig()
    assert not v.patient.enabled
    assert not (v.motion.active or v.sensor_faults.active or v.map_errors.active)
    assert "variations" not in dumps_scenario(Scenario(), only_changes=True)


def test_variations_round_trip_through_yaml(tmp_path):
    trace = tmp_path / "trace.csv"
    trace.write_text("t_s,z_m\n0,0\n1,0.002\n")
    text = f"""
name: varied
variations:
  patient: {{enabled: true, kappa_scale: 0.8, rib_depth_m: 0.012}}
  motion:
    breathing: {{frequency_hz: 0.3, amplitude_m: 0.012, irregularity: 0.2}}
    trace_csv: {trace}
  sensor_faults: {{bias_N: [0, 0, 1.5], dropout_mode: nan, dropout_rate_per_s: 1.0}}
  map_errors: {{kappa_scale: 1.3, shift_x_m: 0.005}}
"""
    s = loads_scenario(text)
    assert s.variations.patient.kappa_scale == 0.8
    assert s.variations.motion.active and s.variations.sensor_faults.active
    assert loads_scenario(dumps_scenario(s)) == s


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: BreathingConfig(frequency_hz=3.0), "frequency_hz"),
        (lambda: BreathingConfig(amplitude_m=-0.001), "amplitude_m"),
        (lambda: BreathingConfig(irregularity=0.9), "irregularity"),
        (lambda: PatientMotionConfig(trace_csv="/no/such.csv"), "does not exist"),
        (lambda: SensorFaultConfig(dropout_mode="zero"), "dropout_mode"),
        (lambda: SensorFaultConfig(stuck_channel=3), "stuck_channel"),
        (lambda: SensorFaultConfig(dead="yes"), r"dead must be true or false"),
        (lambda: SensorFaultConfig(dead_start_s=-1.0), "dead_start_s"),
        (lambda: SensorFaultConfig(bias_N=[1.0, 2.0]), "bias_N"),
        (lambda: SensorFaultConfig(noise_std_N=-1.0), "noise_std_N"),
        (lambda: MapErrorConfig(kappa_scale=0.0), "kappa_scale"),
        (lambda: MapErrorConfig(surface_offset_m=0.5), "surface_offset_m"),
        (lambda: PatientConfig(curvature_scale=-1.0), "curvature_scale"),
        (
            lambda: BreathingConfig(lateral_amplitude_m=[0.02, 0.0]),
            r"lateral_amplitude_m\[0\] must be within \[-0.01, 0.01\] m",
        ),
        (
            lambda: BreathingConfig(lateral_amplitude_m=[0.0, -0.011]),
            r"lateral_amplitude_m\[1\] must be within",
        ),
        (
            lambda: BreathingConfig(lateral_amplitude_m=[0.0, float("nan")]),
            r"lateral_amplitude_m\[1\] must be finite",
        ),
        (
            lambda: BreathingConfig(lateral_amplitude_m=[0.001]),
            r"lateral_amplitude_m must be 2 numbers \[x, y\]",
        ),
        (
            lambda: BreathingConfig(lateral_amplitude_m=[0.001, "left"]),
            r"lateral_amplitude_m\[1\] must be a number",
        ),
    ],
)
def test_bad_values_name_the_field(make, message):
    with pytest.raises(VicDrakeError, match=message):
        make()


def test_lateral_breathing_is_off_by_default_and_on_alone():
    assert not BreathingConfig().lateral_active
    lateral = BreathingConfig(lateral_amplitude_m=[0.0, -0.003])
    assert lateral.lateral_active and lateral.active  # Even with amplitude_m 0.
    s = loads_scenario(
        "variations: {motion: {breathing: "
        "{amplitude_m: 0.01, lateral_amplitude_m: [0.004, -0.002]}}}"
    )
    assert s.variations.motion.lateral_active
    assert s.variations.motion.breathing.lateral_amplitude_m == [0.004, -0.002]
    assert loads_scenario(dumps_scenario(s, only_changes=True)) == s


def test_bad_values_in_yaml_are_caught_at_load():
    with pytest.raises(VicDrakeError, match="amplitude_m"):
        loads_scenario("variations: {motion: {breathing: {amplitude_m: 0.5}}}")
    with pytest.raises(VicDrakeError, match=r"lateral_amplitude_m\[0\]"):
        loads_scenario(
            "variations: {motion: {breathing: {lateral_amplitude_m: [0.05, 0]}}}"
        )
    with pytest.raises(VicDrakeError, match="synthetic"):
        loads_scenario(
            "phantom: {kind: measured}\nvariations: {patient: {enabled: true}}"
        )
