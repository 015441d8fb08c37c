"""Breathing and motion traces (vic_drake.tissue.motion)."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.tissue.motion import (
    breath_cycles,
    breathing_lateral_m,
    breathing_offset_m,
    load_motion_trace,
    trace_offset_m,
)


def _offsets(cycles, t):
    return np.array([breathing_offset_m(x, cycles) for x in t])


def test_regular_breathing_is_a_raised_cosine_of_the_given_rate_and_depth():
    c = breath_cycles(
        frequency_hz=0.25, amplitude_m=0.01, irregularity=0.0, duration_s=20, seed=0
    )
    t = np.linspace(0, 20, 2001)
    z = _offsets(c, t)
    expected = 0.01 * 0.5 * (1 - np.cos(2 * np.pi * 0.25 * t))
    np.testing.assert_allclose(z, expected, atol=1e-12)
    assert z[0] == 0.0  # Starts at rest: no jump of the phantom at t = 0.


def test_irregular_breathing_varies_each_breath_and_stays_continuous():
    c = breath_cycles(
        frequency_hz=0.3, amplitude_m=0.01, irregularity=0.3, duration_s=60, seed=4
    )
    assert np.std(c.period_s) > 0.05 * np.mean(c.period_s)
    assert np.all((c.period_s >= 0.5 / 0.3) & (c.period_s <= 1.5 / 0.3))
    assert np.all((c.amplitude_m >= 0.005) & (c.amplitude_m <= 0.015))
    t = np.arange(0, 60, 0.002)
    z = _offsets(c, t)
    assert np.max(np.abs(np.diff(z))) < 1e-4  # No step between breaths.
    assert c.start_s[-1] + c.period_s[-1] >= 60  # Covers the whole run.
    again = breath_cycles(
        frequency_hz=0.3, amplitude_m=0.01, irregularity=0.3, duration_s=60, seed=4
    )
    np.testing.assert_array_equal(again.period_s, c.period_s)


def test_lateral_part_follows_each_breath_in_phase_scaled_as_its_depth():
    c = breath_cycles(
        frequency_hz=0.3, amplitude_m=0.01, irregularity=0.3, duration_s=30, seed=2
    )
    t = np.arange(0, 30, 0.01)
    z = _offsets(c, t)
    xy = np.array([breathing_lateral_m(x, c, (0.004, -0.002)) for x in t])
    # In phase with the breath, and each breath's excursion is the lateral
    # amplitude times that breath's depth relative to the mean (z / 0.01 m).
    np.testing.assert_allclose(xy[:, 0], 0.004 * z / 0.01, atol=1e-15)
    np.testing.assert_allclose(xy[:, 1], -0.002 * z / 0.01, atol=1e-15)
    np.testing.assert_allclose(c.depth_scale * 0.01, c.amplitude_m)
    assert np.std(c.depth_scale) > 0.05  # Irregular: the breaths differ.
    assert breathing_lateral_m(0.0, c, (0.004, -0.002)) == (0.0, 0.0)
    # Regular breathing: the raised cosine of the given lateral excursion.
    r = breath_cycles(
        frequency_hz=0.25, amplitude_m=0.0, irregularity=0.0, duration_s=10, seed=0
    )
    x = np.array([breathing_lateral_m(v, r, (0.003, 0.0))[0] for v in t[:1000]])
    expected = 0.003 * 0.5 * (1 - np.cos(2 * np.pi * 0.25 * t[:1000]))
    np.testing.assert_allclose(x, expected, atol=1e-15)


def test_motion_trace_reads_interpolates_and_rejects_bad_files(tmp_path):
    good = tmp_path / "trace.csv"
    good.write_text("t_s,z_m\n0,0\n1,0.01\n2,0.0\n")
    table = load_motion_trace(good)
    assert trace_offset_m(0.5, table) == pytest.approx(0.005)
    assert trace_offset_m(9.0, table) == 0.0  # Held after the last row.
    assert trace_offset_m(0.5, table, scale=2.0) == pytest.approx(0.01)
    for text, message in (
        ("t,z\n0,0\n1,0\n", "header"),
        ("t_s,z_m\n0,0\n0,0.01\n", "increase"),
        ("t_s,z_m\n0,0\n1,0.5\n", "0.1"),
        ("t_s,z_m\n0,0\n1,abc\n", "abc"),
    ):
        bad = tmp_path / "bad.csv"
        bad.write_text(text)
        with pytest.raises(VicDrakeError, match=message):
            load_motion_trace(bad)
    with pytest.raises(VicDrakeError, match="does not exist"):
        load_motion_trace(tmp_path / "missing.csv")
