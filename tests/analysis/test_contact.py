"""Contact, the scan window and contact loss on records with known answers."""

import numpy as np
import pytest

from tests.analysis.scans import make_scan
from vic_drake.analysis.contact import contact_loss_intervals, scan_window
from vic_drake.analysis.real_comparison import compare_contact_loss
from vic_drake.analysis.scan_metrics import lifted_off


def test_contact_loss_intervals_ignore_short_dips_and_free_motion():
    t = np.arange(0, 10, 0.002)
    f = np.full(t.size, 5.0)
    f[t < 1] = 0.0  # Approach: not a loss.
    f[(t > 3) & (t < 3.02)] = 0.0  # 20 ms dip: noise, ignored.
    f[(t >= 5) & (t < 6)] = 0.1  # A real loss of 1 s.
    f[t > 9] = 0.0  # Lift-off: not a loss.
    df = make_scan(t, f)
    (loss,) = contact_loss_intervals(df)
    assert loss[0] == pytest.approx(5.0, abs=0.003) and loss[1] == pytest.approx(
        6.0, abs=0.003
    )
    assert lifted_off(df)
    cmp = compare_contact_loss(df, df)
    assert cmp["contact_loss_overlap_s"] == pytest.approx(1.0, abs=0.005)


def test_scan_window_is_the_target_at_scan_height_not_the_contact():
    """A probe still pressing while the target rises (CF cannot lift off) is
    out of the window; a loss of contact inside the scan is in it."""
    t = np.arange(0, 12, 0.01)
    f = np.where(t < 1, 0.0, 7.0)
    f[(t >= 5) & (t < 6)] = 0.0  # Contact lost mid-scan.
    z_d = np.where(t < 10, 0.085, 0.085 + 0.005 * (t - 10))  # Retract from 10 s.
    df = make_scan(t, f, z_d_m=z_d)
    w = scan_window(df)
    assert t[w][0] == pytest.approx(2.0, abs=0.011)
    # The target leaves the 1 mm band 0.2 s into its 5 mm/s retract.
    assert t[w][-1] == pytest.approx(10.2, abs=0.011)
    assert w[(t >= 5) & (t < 6)].all()
    never = make_scan(t, np.zeros_like(t))
    assert not scan_window(never).any()


def test_a_run_that_ends_in_its_approach_has_no_scan_window():
    """Most of a short run's contact can be its approach: the scan height is
    where the target is held, not the median target in contact."""
    t = np.arange(0, 6, 0.002)
    z_d = np.maximum(0.10 - 0.005 * t, 0.085)  # Held at the scan height from 3 s.
    f = np.where(t < 0.5, 0.0, 5.0)  # Touches at 0.5 s, early in the approach.
    w = scan_window(make_scan(t, f, z_d_m=z_d))
    # From where the target is within 1 mm of its scan height (2.8 s).
    assert t[w][0] == pytest.approx(2.8, abs=0.003) and t[w][-1] == t[-1]
    # Cut at 2.5 s, in the approach: the median target in contact (at 1.5 s)
    # is no scan height; there is no scan yet.
    early = t < 2.5
    assert not scan_window(make_scan(t[early], f[early], z_d_m=z_d[early])).any()


def test_contact_loss_clipped_to_the_window_ends_there():
    t = np.arange(0, 12, 0.01)
    f = np.where(t < 1, 0.0, 7.0)
    f[t >= 9] = 0.0  # Lost at 9 s, while the target is still at height ...
    f[t >= 11] = 7.0  # ... and touching again after the window closed.
    z_d = np.where(t < 10, 0.085, 0.095)
    df = make_scan(t, f, z_d_m=z_d)
    (whole,) = contact_loss_intervals(df)
    assert whole == pytest.approx((9.0, 11.0), abs=0.011)
    (clipped,) = contact_loss_intervals(df, window=scan_window(df))
    assert clipped == pytest.approx((9.0, 9.99), abs=0.011)
