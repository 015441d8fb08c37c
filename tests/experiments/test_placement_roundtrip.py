"""compare-real on a simulated log of a phantom placed with a known tilt."""

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.placement_roundtrip import placed_roundtrip


@pytest.mark.realdata
def test_placed_roundtrip_refuses_bad_input(data_dir, tmp_path):
    with pytest.raises(VicDrakeError, match="surface offset"):
        placed_roundtrip(
            data_dir, "test_tracking5", tmp_path, offset_m=0.003,
            slope_m_per_m=0.0, modes=("plane",),
        )  # fmt: skip
    with pytest.raises(VicDrakeError, match="no log"):
        placed_roundtrip(data_dir, "nope", tmp_path, offset_m=0.0, slope_m_per_m=0.0)


@pytest.mark.slow
@pytest.mark.realdata
def test_a_known_tilt_is_read_back_and_fixes_kz(data_dir, tmp_path):
    """nardi's scan on the map placed 3 mm up and tilted +20 mm/m along x
    (its real tilt is +17): the plane is read back within 0.1 mm over the
    track, and the simulated K_z and tip height follow the log, where the
    first contact's constant leaves K_z at 0.907 and the tip 2 mm off
    (measured: placement 0.990 / 0.09 mm)."""
    first, placed = placed_roundtrip(
        data_dir,
        "test_nardi_matForce_lowR",
        tmp_path,
        offset_m=0.003,
        slope_m_per_m=0.020,
        modes=("first contact", "placement"),
    )
    assert placed["surface_offset_source"] == "placement"
    assert placed["placement_slope_mm_per_m"] == pytest.approx(20.0, abs=0.5)
    assert abs(placed["placement_max_err_mm"]) < 0.1
    assert placed["kz_corr"] > 0.98 and first["kz_corr"] < 0.93
    assert placed["z_rmse_mm"] < 0.3 and first["z_rmse_mm"] > 1.5
    assert placed["force_rmse_N"] <= first["force_rmse_N"]
