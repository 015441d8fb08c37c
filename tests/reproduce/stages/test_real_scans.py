"""The ``real_scans`` stage: the paper's scan logs in the canonical columns."""

import pytest

from vic_drake.reproduce import REAL_SCAN_LOGS, real_scan_frame


@pytest.mark.realdata
def test_real_scan_frame_layouts(data_dir):
    from vic_drake.realdata import read_bag

    cf = real_scan_frame(
        read_bag(data_dir / "experiments" / REAL_SCAN_LOGS[("nominal", "cf")]),
        controller="cf",
    )
    assert (cf["force_ref_z_N"] == -7.0).all()
    assert cf["force_sensor_z_N"].median() < 0  # pressing: negative in sensor sign
    vsvf = real_scan_frame(
        read_bag(data_dir / "experiments" / REAL_SCAN_LOGS[("nominal", "vs-vf")])
    )
    # Tank power = change per tick / tick period; the valve holds it near -0.1 W.
    assert vsvf["tank_power_W"].min() == pytest.approx(-0.1, abs=0.01)
