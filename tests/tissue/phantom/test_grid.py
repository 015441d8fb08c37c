"""GridPhantom: bilinear and nearest lookup, clamping, validation."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.tissue import GridPhantom

from .planes import plane_phantom


def test_grid_bilinear_is_exact_on_planes():
    p = plane_phantom()
    s = p.sample(0.0437, 0.0213)
    assert s.surface_z_m == pytest.approx(0.1 + 0.2 * 0.0437 - 0.1 * 0.0213)
    assert s.kappa == pytest.approx(1000 + 1e4 * 0.0437)
    assert s.dz_dx == pytest.approx(0.2)
    assert s.dz_dy == pytest.approx(-0.1)


def test_grid_clamps_outside_and_zeroes_gradient_across_edge():
    p = plane_phantom()
    s = p.sample(0.5, 0.02)
    assert s.surface_z_m == pytest.approx(0.1 + 0.2 * 0.1 - 0.1 * 0.02)
    assert s.dz_dx == 0.0
    assert s.dz_dy == pytest.approx(-0.1)


def test_grid_surface_offset_and_nearest_lookup():
    p = plane_phantom(surface_offset_m=0.0025, lookup="nearest")
    assert p.surface_z(0.0437, 0.0213) == pytest.approx(
        0.1 + 0.2 * 0.04 - 0.1 * 0.02 + 0.0025
    )


def test_grid_rejects_bad_shapes():
    with pytest.raises(VicDrakeError, match="kappa has shape"):
        GridPhantom(
            x_m=[0, 1],
            y_m=[0, 1],
            z_m=np.zeros((2, 2)),
            kappa=np.zeros((3, 2)),
            lam=np.zeros((2, 2)),
        )
