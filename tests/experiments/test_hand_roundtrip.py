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
