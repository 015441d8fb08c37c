"""Sensor fault models (vic_drake.control.sensor_faults)."""

import numpy as np
import pytest

from vic_drake.control.sensor_faults import fault_schedule, faulty_reading


def _read(schedule, u, k, **kw):
    args = dict(
        tick=k,
        t_s=k * 0.002,
        schedule=schedule,
        bias_N=np.zeros(3),
        stuck_channel=-1,
        stuck_start_s=0.0,
        stuck_value_N=np.nan,
        previous_N=np.array([9.0, 9.0, 9.0]),
        dropout_mode="hold",
    )
    args.update(kw)
    return faulty_reading(np.asarray(u, float), **args)


def test_schedule_rates_match_their_parameters():
    s = fault_schedule(
        ticks=500_000,
        period_s=0.002,
        seed=1,
        noise_std_N=0.5,
        spike_rate_per_s=2.0,
        spike_magnitude_N=10.0,
        dropout_rate_per_s=1.0,
        dropout_duration_s=0.05,
    )
    assert np.std(s.noise_N) == pytest.approx(0.5, rel=0.01)
    n_spikes = np.count_nonzero(np.linalg.norm(s.spikes_N, axis=1))
    assert n_spikes == pytest.approx(2.0 * 1000, rel=0.1)  # 1000 s of ticks.
    np.testing.assert_allclose(
        np.linalg.norm(s.spikes_N[np.any(s.spikes_N, 1)], axis=1), 10.0
    )
    # Dropout share ~ rate x duration (overlaps make it a bit less).
    assert s.dropout.mean() == pytest.approx(0.05, rel=0.15)
    again = fault_schedule(ticks=500_000, period_s=0.002, seed=1, noise_std_N=0.5)
    np.testing.assert_array_equal(again.noise_N, s.noise_N)


def test_reading_bias_stuck_and_dropouts():
    quiet = fault_schedule(ticks=10, period_s=0.002, seed=0)
    y = _read(quiet, [1, 2, 3], 0, bias_N=np.array([0.5, 0, -1]))
    np.testing.assert_allclose(y, [1.5, 2, 2])
    y = _read(
        quiet, [1, 2, 3], 5, stuck_channel=2, stuck_start_s=0.001, stuck_value_N=7.0
    )
    np.testing.assert_allclose(y, [1, 2, 7])
    drop = fault_schedule(
        ticks=10,
        period_s=0.002,
        seed=0,
        dropout_rate_per_s=1e6,
        dropout_duration_s=0.02,
    )
    assert drop.dropout.all()
    np.testing.assert_allclose(_read(drop, [1, 2, 3], 3), [9, 9, 9])
    assert np.isnan(_read(drop, [1, 2, 3], 3, dropout_mode="nan")).all()


def test_a_dead_sensor_is_a_dropout_that_never_ends():
    quiet = fault_schedule(ticks=10, period_s=0.002, seed=0)
    # Before it dies the reading is live; from dead_start_s on it is the
    # last delivered value, or NaN, at every tick (the schedule wraps).
    np.testing.assert_allclose(_read(quiet, [1, 2, 3], 4, dead_start_s=0.01), [1, 2, 3])
    for k in (5, 6, 25, 1000):
        np.testing.assert_allclose(
            _read(quiet, [1, 2, 3], k, dead_start_s=0.01), [9, 9, 9]
        )
        assert np.isnan(
            _read(quiet, [1, 2, 3], k, dead_start_s=0.01, dropout_mode="nan")
        ).all()
