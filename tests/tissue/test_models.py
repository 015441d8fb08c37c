import numpy as np
import pytest

from vic_drake.tissue import (
    hunt_crossley_force,
    hunt_crossley_penetration,
    kelvin_voigt_force,
)


def test_hunt_crossley_analytic():
    # 1 cm at rest: kappa * 0.01^1.35.
    f = hunt_crossley_force(0.01, 0.0, 5000.0, 40000.0, 1.35)
    assert f == pytest.approx(5000.0 * 0.01**1.35, rel=1e-12)
    # Moving in at 2 cm/s adds lam eps^beta eps_dot.
    f = hunt_crossley_force(0.01, 0.02, 5000.0, 40000.0, 1.35)
    assert f == pytest.approx(0.01**1.35 * (5000.0 + 40000.0 * 0.02), rel=1e-12)


def test_hunt_crossley_zero_out_of_contact_and_vectorised():
    eps = np.array([-0.01, 0.0, 0.005])
    f = hunt_crossley_force(eps, np.array([1.0, 1.0, 0.0]), 1000.0, 1e4, 1.5)
    np.testing.assert_allclose(f, [0.0, 0.0, 1000.0 * 0.005**1.5])


def test_hunt_crossley_tension_clip():
    # Fast withdrawal: the raw law goes negative, the clipped law does not.
    raw = hunt_crossley_force(0.01, -1.0, 1000.0, 1e4, 1.35)
    assert raw < 0
    assert hunt_crossley_force(0.01, -1.0, 1000.0, 1e4, 1.35, clip_tension=True) == 0.0


def test_kelvin_voigt():
    np.testing.assert_allclose(
        kelvin_voigt_force([-0.001, 0.01], [0.0, 0.1], 500.0, 20.0), [0.0, 7.0]
    )


def test_penetration_inverts_elastic_part():
    eps = hunt_crossley_penetration(7.0, 5400.0, 1.35)
    assert hunt_crossley_force(eps, 0.0, 5400.0, 0.0, 1.35) == pytest.approx(7.0)
