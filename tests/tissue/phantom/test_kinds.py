"""load_phantom: the kinds, and the measured map from the data folder."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.tissue import load_phantom


def test_load_phantom_kind_error():
    with pytest.raises(VicDrakeError, match="phantom kind must be one of"):
        load_phantom("banana")


def test_measured_map(data_dir):
    p = load_phantom("measured", data_dir=data_dir)
    assert p.kappa_grid.shape == (202, 103)
    assert p.kappa_grid.min() == pytest.approx(1986.67, abs=0.1)
    # The real controller's tissue surface is map z + 2.5 mm.
    assert p.surface_z(p.x_m[5], p.y_m[7]) == pytest.approx(p.surface_m[5, 7])
    assert p.surface_m[5, 7] - 0.0025 == pytest.approx(
        np.loadtxt(data_dir / "phantom_map" / "z.txt")[5 * 103 + 7]
    )
