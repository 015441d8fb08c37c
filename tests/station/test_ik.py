"""Probe-tip inverse and forward kinematics."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.station import (
    initial_q_for_tip,
    probe_down_rotation,
    probe_pose,
    solve_tip_ik,
)


def test_world_is_the_rigs_base_link_and_ik_points_the_probe_down():
    p = np.array([-0.1, -0.36, 0.1])  # inside the measured map, above the surface
    q = solve_tip_ik(p)
    X_WP = probe_pose(q)
    np.testing.assert_allclose(X_WP.translation(), p, atol=1e-5)
    np.testing.assert_allclose(
        X_WP.rotation().matrix(), probe_down_rotation().matrix(), atol=1e-5
    )
    # z of the probe points down, as the real controller's target (x = 1, w = 0).
    np.testing.assert_allclose(X_WP.rotation().matrix()[:, 2], [0, 0, -1], atol=1e-5)


def test_unreachable_tip_is_a_clear_error():
    with pytest.raises(VicDrakeError, match="no joint configuration"):
        initial_q_for_tip([2.0, 0.0, 0.1])
