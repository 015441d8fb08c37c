"""The synthetic chest: ranges, ribs, gradient, parameter checks."""

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.tissue import SyntheticChestParams, SyntheticChestPhantom


def test_synthetic_in_measured_ranges():
    p = SyntheticChestPhantom()
    _, _, s = p.rasterize(0.002)
    # The measured GP map spans kappa 1,987-10,236 and lambda 16,778-210,595.
    assert 1900 < s.kappa.min() and s.kappa.max() < 10300
    assert 16000 < s.lam.min() and s.lam.max() < 215000
    x_min, x_max, y_min, y_max = p.bounds
    assert x_max - x_min == pytest.approx(0.33) and y_max - y_min == pytest.approx(0.33)


def test_synthetic_ribs_stand_out_and_muscle_rib_is_softer():
    p = SyntheticChestPhantom()
    y = p.params.center_y_m
    peaks = [float(p.kappa(xc, y)) for xc in p.rib_centres_x(y)]
    between = float(p.kappa(p.rib_centres_x(y)[1] + 0.02, y))
    assert min(peaks) > 1.5 * between
    muscle = peaks[p.params.muscle_rib_index]
    assert muscle < 0.8 * min(
        v for i, v in enumerate(peaks) if i != p.params.muscle_rib_index
    )


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
