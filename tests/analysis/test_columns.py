"""The real logs in the canonical layout."""

import numpy as np
import pytest

from vic_drake.analysis.columns import CANONICAL_COLUMNS, real_to_canonical
from vic_drake.analysis.scan_metrics import force_rmse_N, tank_min_J
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import read_bag


@pytest.mark.realdata
def test_real_logs_convert_to_the_canonical_layout(data_dir):

    real = real_to_canonical(read_bag(data_dir / "experiments" / "test_tracking5"))
    assert tuple(real.columns) == CANONICAL_COLUMNS
    # VS-CF at a 7 N reference: the real controller tracked it to within ~1 N.
    assert force_rmse_N(real) < 1.5
    assert tank_min_J(real) == pytest.approx(0.9708, abs=1e-3)
    cs = real_to_canonical(
        read_bag(data_dir / "experiments" / "test_compliance_control400")
    )
    assert np.isnan(cs["x_d_m"]).all() and (cs["force_sensor_z_N"] < 0).all()
    with pytest.raises(VicDrakeError, match="layout"):
        real_to_canonical(read_bag(data_dir / "palpation" / "test_soft_1hz"))
