"""The synthetic chest: ranges, ribs, gradient, parameter checks."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.tissue import SyntheticChestParams, SyntheticChestPhantom


def test_synthetic_in_measured_ranges():
    p = SyntheticChestPhantom()
    # Over the measured map's footprint (where the twin was fitted) kappa and
    # lambda stay in the measured map's ranges (kappa 1,987-10,236, lambda
    # 16,778-210,595).
    X, Y = np.meshgrid(
        np.linspace(-0.1587, 0.0423, 101), np.linspace(-0.4145, -0.3125, 52)
    )
    s = p.sample(X, Y)
    assert 1900 < s.kappa.min() and s.kappa.max() < 10300
    assert 16000 < s.lam.min() and s.lam.max() < 215000
    assert 0.07 < s.surface_z_m.min() and s.surface_z_m.max() < 0.125
    x_min, x_max, y_min, y_max = p.bounds
    assert x_max - x_min == pytest.approx(0.33) and y_max - y_min == pytest.approx(0.33)


def test_synthetic_ribs_stand_out_and_muscle_rib_is_softer():
    p = SyntheticChestPhantom()
    y = p.params.center_y_m
    centres = p.rib_centres_x(y)
    peaks = [float(p.kappa(xc, y)) for xc in centres]
    between = [float(p.kappa(0.5 * (a + b), y)) for a, b in zip(centres, centres[1:])]
    muscle = p.params.muscle_rib_index
    others = [v for i, v in enumerate(peaks) if i != muscle]
    # Bare ribs rise at least 30 % over the tissue beside them; the rib under
    # the muscle still stands out, but less than any bare rib.
    assert min(others) > 1.3 * max(between)
    assert max(between) < peaks[muscle] < min(others)


def test_synthetic_gradient_matches_finite_difference():
    p = SyntheticChestPhantom()
    h = 1e-4
    x, y = -0.03, -0.40
    s = p.sample(x, y)
    assert s.dz_dx == pytest.approx(
        (p.surface_z(x + h, y) - p.surface_z(x - h, y)) / (2 * h), rel=1e-4
    )
    assert s.dz_dy == pytest.approx(
        (p.surface_z(x, y + h) - p.surface_z(x, y - h)) / (2 * h), rel=1e-4
    )


def test_synthetic_params_validated():
    with pytest.raises(VicDrakeError, match="kappa_rib"):
        SyntheticChestParams(kappa_rib=100.0)
