"""One field's GP map on a grid (fixtures in conftest.py)."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.gp_fit import GpMapParams
from vic_drake.estimation.gp_grid import gp_map
from vic_drake.estimation.tissue_map import map_axis

from .gp_samples import field


def test_gp_map_recovers_a_smooth_field(samples):
    xs, ys = map_axis(0.0, 0.1, 0.002), map_axis(0.0, 0.08, 0.002)
    m = gp_map(*samples, xs, ys)
    truth = field(*np.meshgrid(xs, ys, indexing="ij"))
    rel = np.sqrt(np.mean(((m.mean - truth) / truth) ** 2))
    assert rel < 0.02
    assert m.mean.shape == m.std.shape == (xs.size, ys.size)
    # The std is the uncertainty of the field: small near data, within 1 %.
    assert np.median(m.std) < 0.02 * 4000.0


def test_log_target_map_is_positive_and_accurate(samples):
    xs, ys = map_axis(0.0, 0.1, 0.005), map_axis(0.0, 0.08, 0.005)
    m = gp_map(*samples, xs, ys, GpMapParams(log_target=True, n_restarts=1))
    truth = field(*np.meshgrid(xs, ys, indexing="ij"))
    assert np.all(m.mean > 0) and np.all(m.std >= 0)
    assert np.sqrt(np.mean(((m.mean - truth) / truth) ** 2)) < 0.03
    x, y, v = samples
    with pytest.raises(VicDrakeError, match="positive"):
        gp_map(x, y, v - 10_000.0, xs, ys, GpMapParams(log_target=True))
