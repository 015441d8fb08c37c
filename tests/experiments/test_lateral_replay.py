"""compare-real's lateral passes: the corrected target and the rerun."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.lateral_replay import (
    check_lateral_passes,
    corrected_waypoints,
    lateral_rms_mm,
    resolve_lateral_passes,
)


def _frames(offset_x=0.004, offset_y=-0.002, n=2001, dt=0.002):
    t = np.arange(n) * dt
    x_d = 0.03 - 0.01 * t
    # The simulated tip lags its target by 15 mm; the real one was pushed
    # ahead of that by offset_x and sideways by offset_y.
    sim = pd.DataFrame(
        {
            "t_s": t,
            "x_m": x_d + 0.015,
            "y_m": np.full(n, -0.36),
            "x_d_m": x_d,
            "y_d_m": np.full(n, -0.36),
            "z_d_m": np.full(n, 0.085),
        }
    )
    real = pd.DataFrame(
        {
            "t_s": t,
            "x_m": sim["x_m"] + offset_x,
            "y_m": sim["y_m"] + offset_y,
        }
    )
    return sim, real


def test_the_target_moves_by_the_lateral_error_and_keeps_its_height():
    sim, real = _frames()
    wp = np.array(corrected_waypoints(sim, real))
    t = wp[:, 0]
    assert np.allclose(np.diff(t), 0.02)
    assert np.allclose(wp[:, 1], 0.03 - 0.01 * t + 0.004, atol=1e-12)
    assert np.allclose(wp[:, 2], -0.36 - 0.002, atol=1e-12)
    assert np.allclose(wp[:, 3], 0.085)


def test_the_lateral_error_is_smoothed_over_two_tenths_of_a_second():
    sim, real = _frames(offset_x=0.0, offset_y=0.0)
    # A 10 mm, 20 ms spike in the real x: the 0.2 s average keeps about a tenth.
    spike = (real["t_s"] >= 2.0) & (real["t_s"] < 2.02)
    real.loc[spike, "x_m"] += 0.010
    wp = np.array(corrected_waypoints(sim, real))
    moved = wp[:, 1] - (0.03 - 0.01 * wp[:, 0])
    assert moved.max() == pytest.approx(0.010 / 11, rel=0.05)
    assert np.abs(moved[np.abs(wp[:, 0] - 2.0) > 0.2]).max() < 1e-12


def test_the_lateral_rms_is_the_horizontal_distance():
    sim, real = _frames(offset_x=0.003, offset_y=0.004)
    window = np.ones(len(real), bool)
    assert lateral_rms_mm(sim, real, window) == pytest.approx(5.0)
    assert np.isnan(lateral_rms_mm(sim, real, np.zeros(len(real), bool)))
    # Only the real samples the simulation reached count.
    short = sim[sim["t_s"] <= 1.0]
    far = real.copy()
    far.loc[far["t_s"] > 1.0, "x_m"] += 1.0
    assert lateral_rms_mm(short, far, window) == pytest.approx(5.0)


@pytest.mark.parametrize("bad", [-1, 4, 1.5, True, "1", None])
def test_bad_pass_counts_are_refused(bad):
    with pytest.raises(VicDrakeError, match="lateral_passes"):
        check_lateral_passes(bad)


def test_auto_runs_one_pass_only_when_the_motion_is_replayed():
    assert check_lateral_passes("auto") == "auto"
    assert resolve_lateral_passes("auto", replayed=True) == 1
    assert resolve_lateral_passes("auto", replayed=False) == 0
    assert resolve_lateral_passes(2, replayed=False) == 2
    assert resolve_lateral_passes(0, replayed=True) == 0
    with pytest.raises(VicDrakeError, match="lateral_passes"):
        resolve_lateral_passes("Auto", replayed=True)


def test_non_finite_tip_positions_are_refused():
    sim, real = _frames()
    real.loc[5, "y_m"] = np.nan
    with pytest.raises(VicDrakeError, match="real tip"):
        corrected_waypoints(sim, real)


@pytest.mark.realdata
def test_compare_real_refuses_bad_lateral_passes_before_simulating(data_dir):
    from vic_drake.experiments.compare_real import compare_real

    with pytest.raises(VicDrakeError, match="lateral_passes"):
        compare_real(data_dir / "experiments" / "test_force_control", lateral_passes=7)


@pytest.mark.realdata
@pytest.mark.slow
def test_a_lateral_pass_brings_the_simulated_tip_onto_the_real_path(data_dir):
    # The first lift of test_force_control_dist starts about 2 s into the log;
    # over the scored part of its first 5 s the tips are 3.6 mm apart (RMS)
    # and one pass brings them to 1.9 mm (measured); a correction of the
    # wrong sign or size would not.
    from vic_drake.experiments.compare_real import compare_real

    lines = []
    out = compare_real(
        data_dir / "experiments" / "test_force_control_dist",
        data_dir=data_dir,
        duration_s=5.0,
        lateral_passes=1,
        progress=lines.append,
    )
    assert out["lateral_passes"] == 1
    before, after = out["lateral_rms_mm"]
    assert before > 1.0
    assert after < 0.6 * before
    # The progress says which run is the pass, and what it corrects.
    (line,) = [x for x in lines if x.startswith("lateral pass")]
    assert line == (
        "lateral pass 1 of 1: the path corrected by the last run's lateral "
        f"error ({before:.2f} mm RMS)"
    )
