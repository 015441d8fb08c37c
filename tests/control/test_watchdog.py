"""The force sensor's watchdog: what trips it, what does not, and the retract."""

import numpy as np
import pytest

from vic_drake.control.watchdog import (
    DEAD_SENSOR,
    FROZEN_RUN,
    STUCK_CHANNEL,
    TRIP_TIME,
    TRIPPED,
    SensorWatchdogParams,
    initial_watchdog_state,
    record_trip,
    retract_target,
    watch_reading,
)
from vic_drake.errors import VicDrakeError

WINDOW = 25
DEAD = 100


def _feed(readings, window=WINDOW, dead=DEAD):
    """The tick of each trip (and its channel) over ``readings`` (n, 3)."""
    state = initial_watchdog_state()
    trips = []
    for k, reading in enumerate(readings):
        channel = watch_reading(state, reading, window, dead)
        if channel >= 0:
            record_trip(state, channel, 0.002 * k, [0.0, 0.0, 0.1])
            trips.append((k, channel))
    return trips, state


def _noisy(n, seed=0, std=0.05):
    return std * np.random.default_rng(seed).standard_normal((n, 3)) + [0, 0, -7]


@pytest.mark.parametrize("channel", [0, 1, 2])
def test_a_channel_stuck_while_the_others_change_trips_after_the_window(channel):
    readings = _noisy(400)
    readings[100:, channel] = readings[100, channel]
    trips, state = _feed(readings)
    # Sample 100 sets the value; 101 .. 125 keep it: 25 live ticks.
    assert trips == [(100 + WINDOW, channel)]
    assert state[TRIPPED] == 1.0 and state[STUCK_CHANNEL] == channel
    assert state[TRIP_TIME] == pytest.approx(0.002 * (100 + WINDOW))


def test_a_healthy_noisy_sensor_never_trips():
    assert _feed(_noisy(50_000, seed=3))[0] == []


def test_a_kept_value_one_tick_short_of_the_window_does_not_trip():
    readings = _noisy(400, seed=1)
    for start in (50, 150, 250):  # 24 live ticks each, then it moves again.
        readings[start : start + WINDOW, 2] = readings[start, 2]
    assert _feed(readings)[0] == []


def test_whole_samples_repeated_are_no_stuck_evidence_and_do_not_reset_the_count():
    # A held dropout (every channel at once) shorter than the dead window.
    readings = _noisy(600, seed=2)
    readings[100:199] = readings[100]
    assert _feed(readings)[0] == []
    # A stuck z across a held dropout: the live ticks before and after it
    # add up (291..300 before, 380..394 after: 25).
    readings = _noisy(600, seed=2)
    readings[290:, 2] = readings[290, 2]
    readings[300:380] = readings[300]
    trips, _ = _feed(readings)
    assert trips == [(394, 2)]


def test_a_reading_that_stops_changing_is_a_dead_sensor():
    # Sample 100 is the last new one; 101 .. 200 repeat it: the dead window.
    readings = _noisy(600, seed=6)
    readings[100:] = readings[100]
    trips, state = _feed(readings)
    assert trips == [(100 + DEAD, DEAD_SENSOR)]
    assert state[STUCK_CHANNEL] == DEAD_SENSOR
    # One tick short of the window, then a new reading: no trip, and the
    # next frozen spell counts from zero.
    readings = _noisy(600, seed=6)
    readings[100:200] = readings[100]
    readings[300:400] = readings[300]
    trips, state = _feed(readings)
    assert trips == []
    assert state[FROZEN_RUN] == 0


def test_a_sensor_that_delivers_no_finite_reading_is_dead():
    readings = _noisy(400, seed=7)
    readings[50:] = np.nan
    assert _feed(readings)[0] == [(50 + DEAD - 1, DEAD_SENSOR)]
    # A NaN spell and a repeat of the last finite reading add up: nothing new.
    readings = _noisy(400, seed=7)
    readings[50:100] = np.nan
    readings[100:] = readings[49]
    assert _feed(readings)[0] == [(50 + DEAD - 1, DEAD_SENSOR)]


def test_a_still_sensor_without_noise_is_dead_after_the_window():
    # A real sensor's noise never keeps a whole reading (the rig's longest
    # repeat is 6 samples); the simulated noiseless sensor does not either
    # (docs/decisions.md, "The dead sensor").
    readings = np.tile([0.0, 0.0, -0.3], (1000, 1))
    assert _feed(readings)[0] == [(DEAD - 1, DEAD_SENSOR)]


def test_non_finite_readings_are_skipped():
    readings = _noisy(300, seed=4)
    readings[100:, 2] = readings[100, 2]
    readings[110:140] = np.nan  # A NaN dropout inside the stuck run.
    trips, _ = _feed(readings)
    # 101..109 (9 live ticks), NaN skipped, the count goes on from 140.
    assert trips == [(140 + WINDOW - 9 - 1, 2)]


def test_a_tripped_watchdog_stays_tripped_and_reads_no_more():
    readings = _noisy(400, seed=5)
    readings[:200, 1] = readings[0, 1]
    trips, state = _feed(readings)
    assert trips == [(WINDOW, 1)]
    last = state.copy()
    assert watch_reading(state, [1.0, 2.0, 3.0], WINDOW, DEAD) == -1
    np.testing.assert_array_equal(state, last)


def test_retract_lifts_from_the_trip_position_at_its_speed_then_holds():
    params = SensorWatchdogParams(retract_speed_m_per_s=0.03, retract_height_m=0.03)
    state = initial_watchdog_state()
    record_trip(state, 2, 1.0, [0.1, -0.4, 0.08])
    np.testing.assert_allclose(retract_target(state, 1.0, params), [0.1, -0.4, 0.08])
    np.testing.assert_allclose(retract_target(state, 1.5, params), [0.1, -0.4, 0.095])
    np.testing.assert_allclose(retract_target(state, 9.0, params), [0.1, -0.4, 0.11])


def test_window_in_ticks():
    assert SensorWatchdogParams(stuck_window_s=0.05).window_ticks(0.002) == 25
    assert SensorWatchdogParams(stuck_window_s=0.051).window_ticks(0.002) == 26
    assert SensorWatchdogParams(stuck_window_s=1e-4).window_ticks(0.002) == 2
    assert SensorWatchdogParams().dead_ticks(0.002) == 50


@pytest.mark.parametrize(
    "field, value",
    [
        ("stuck_window_s", 0.0),
        ("dead_window_s", float("inf")),
        ("retract_speed_m_per_s", -0.01),
        ("retract_height_m", float("nan")),
        ("retract_stiffness_N_per_m", True),
        ("enabled", "yes"),
    ],
)
def test_bad_settings_name_the_field(field, value):
    with pytest.raises(VicDrakeError, match=f"SensorWatchdogParams.{field}"):
        SensorWatchdogParams(**{field: value})


def _scan_forces(data_dir, name):
    from vic_drake.realdata import read_bag

    df = read_bag(data_dir / "experiments" / name)
    cols = ["sensor_force_x_N", "sensor_force_y_N", "sensor_force_z_N"]
    return df[cols].to_numpy(float)


@pytest.mark.parametrize("name", ["test_tracking5", "test_nardi_matForce_lowR"])
def test_the_rigs_scans_never_trip_it(data_dir, name):
    # The rig's sensor, as logged in its two scans with all three channels:
    # no channel ever keeps its value while another changes, so not even a
    # window of two ticks trips; whole samples repeat at most 6 times in a
    # row (the logger read one sample twice), far inside the dead window.
    forces = _scan_forces(data_dir, name)
    assert _feed(forces, window=2)[0] == []
    assert _feed(forces, window=2, dead=8)[0] == []


_ONE_CHANNEL_LOGS = {
    "experiments": [
        "test_compliance_control400",
        "test_compliance_control400_dist",
        "test_force_control",
        "test_force_control_dist",
    ],
    "loadcycle": ["test_soft_1", "test_soft_2", "test_soft_3"],
    "palpation": ["test_soft_1hz", "test_soft_2hz", "test_soft_25hz"],
}


@pytest.mark.parametrize(
    "folder, name",
    [(folder, name) for folder, names in _ONE_CHANNEL_LOGS.items() for name in names],
)
def test_the_rigs_one_channel_logs_never_look_dead(data_dir, folder, name):
    # The other ten logs hold the z force only (longest repeat: 5 samples).
    # Fed as the same value on every channel, only the dead rule can trip,
    # and not even a window of 10 ticks (0.02 s) does.
    from vic_drake.realdata import read_bag

    df = read_bag(data_dir / folder / name)
    column = "force_pressing_z_N" if folder == "experiments" else "force_z_N"
    z = df[column].to_numpy(float)
    assert _feed(np.repeat(z[:, None], 3, axis=1), dead=10)[0] == []
