"""compare-real on a simulated hand-moved log whose motion is known."""

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.hand_roundtrip import hand_lifts, hand_moved_roundtrip


def test_hand_events_lift_then_drop_below_rest_after_the_first_contact():
    lifts = hand_lifts(3, 2, 2.5)
    assert len(lifts) == 4
    assert lifts[0].start_s == 2.5
    ups, downs = lifts[0::2], lifts[1::2]
    assert all(0.005 <= lift.height_m <= 0.015 for lift in ups)
    assert all(-0.012 <= lift.height_m <= -0.006 for lift in downs)
    assert all(0.12 <= lift.rise_s <= 0.25 for lift in downs)  # Faster than the probe.
    assert hand_lifts(3, 2, 2.5) == lifts  # Seeded.


@pytest.mark.realdata
@pytest.mark.parametrize("events", [0, 9, 2.0, True])
def test_bad_event_counts_are_refused_before_simulating(data_dir, tmp_path, events):
    with pytest.raises(VicDrakeError, match="events"):
        hand_moved_roundtrip(data_dir, "test_force_control", 0, events, tmp_path)


@pytest.mark.realdata
@pytest.mark.slow
def test_a_hand_moved_cs_log_is_reproduced_with_its_contact_losses(data_dir, tmp_path):
    # Measured at the commit that added it: 0.461 N, loss 0.922 s against
    # the log's 0.752 s, all of it at the same time; with the gap held at the
    # loose bound (the code before) 0.419 N but only 0.416 s of the loss.
    out = hand_moved_roundtrip(data_dir, "test_compliance_control400", 2, 5, tmp_path)
    assert out["loss_real_s"] > 0.3, "the drops should lose contact"
    assert out["loss_overlap_s"] >= 0.9 * out["loss_real_s"]
    assert abs(out["loss_sim_s"] - out["loss_real_s"]) <= 0.3 * out["loss_real_s"]
    assert out["force_rmse_N"] < 0.8
    assert out["est_rms_contact_mm"] < 1.0


@pytest.mark.realdata
@pytest.mark.slow
def test_a_short_hand_moved_log_is_replayed(data_dir, tmp_path):
    # Two events in 10.8 s: 8.7 % of the samples beyond 3 sigma, under the
    # 10 % that alone decided before, so a resting phantom was simulated
    # (3.39 N, the 0.114 s loss missed). Two runs of 0.46 and 0.48 s beyond
    # 3 sigma make it significant now: 0.381 N, 0.152 s of loss, all of the
    # log's at the same time (measured at the commit that added it).
    out = hand_moved_roundtrip(data_dir, "test_compliance_control400", 2, 2, tmp_path)
    assert out["motion_significance"] < 0.1
    assert out["motion_replayed"] is True
    assert out["loss_real_s"] > 0.05, "the drop should lose contact"
    assert out["loss_overlap_s"] >= 0.9 * out["loss_real_s"]
    assert out["force_rmse_N"] < 0.8
