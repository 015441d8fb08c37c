import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.tissue import (
    GridPhantom,
    SyntheticChestParams,
    SyntheticChestPhantom,
    load_phantom,
)


def _plane_phantom(**kwargs):
    x = np.linspace(0.0, 0.1, 11)
    y = np.linspace(0.0, 0.05, 6)
    X, Y = np.meshgrid(x, y, indexing="ij")
    return GridPhantom(
        x_m=x, y_m=y, z_m=0.1 + 0.2 * X - 0.1 * Y, kappa=1000 + 1e4 * X,
        lam=2e4 + 0 * X, beta=1.35, **kwargs,
    )


def test_grid_bilinear_is_exact_on_planes():
    p = _plane_phantom()
    s = p.sample(0.0437, 0.0213)
    assert s.surface_z_m == pytest.approx(0.1 + 0.2 * 0.0437 - 0.1 * 0.0213)
    assert s.kappa == pytest.approx(1000 + 1e4 * 0.0437)
    assert s.dz_dx == pytest.approx(0.2)
    assert s.dz_dy == pytest.approx(-0.1)


def test_grid_clamps_outside_and_zeroes_gradient_across_edge():
    p = _plane_phantom()
    s = p.sample(0.5, 0.02)
    assert s.surface_z_m == pytest.approx(0.1 + 0.2 * 0.1 - 0.1 * 0.02)
    assert s.dz_dx == 0.0
    assert s.dz_dy == pytest.approx(-0.1)


def test_grid_surface_offset_and_nearest_lookup():
    p = _plane_phantom(surface_offset_m=0.0025, lookup="nearest")
    assert p.surface_z(0.0437, 0.0213) == pytest.approx(0.1 + 0.2 * 0.04 - 0.1 * 0.02 + 0.0025)


def test_grid_rejects_bad_shapes():
    with pytest.raises(VicDrakeError, match="kappa has shape"):
        GridPhantom(x_m=[0, 1], y_m=[0, 1], z_m=np.zeros((2, 2)), kappa=np.zeros((3, 2)),
                    lam=np.zeros((2, 2)))


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
    assert muscle < 0.8 * min(v for i, v in enumerate(peaks) if i != p.params.muscle_rib_index)


def test_synthetic_gradient_matches_finite_difference():
    p = SyntheticChestPhantom()
    h = 1e-4
    x, y = -0.03, -0.40
    s = p.sample(x, y)
    assert s.dz_dx == pytest.approx((p.surface_z(x + h, y) - p.surface_z(x - h, y)) / (2 * h), rel=1e-4)
    assert s.dz_dy == pytest.approx((p.surface_z(x, y + h) - p.surface_z(x, y - h)) / (2 * h), rel=1e-4)


def test_synthetic_params_validated():
    with pytest.raises(VicDrakeError, match="kappa_rib"):
        SyntheticChestParams(kappa_rib=100.0)


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
        np.loadtxt(data_dir / "phantom_map" / "z.txt")[5 * 103 + 7])


def test_point_lookup_cached_per_phantom_and_mode():
    import copy

    p = _plane_phantom()
    fast = p.point_lookup()
    assert p.point_lookup() is fast
    assert fast(0.0437, 0.0213) == pytest.approx(tuple(
        float(v) for v in vars(p.sample(0.0437, 0.0213)).values()))
    # A copy switched to nearest lookup must not reuse the bilinear lookup.
    q = copy.copy(p)
    q.lookup = "nearest"
    assert q.point_lookup() is not fast
    assert q.point_lookup()(0.0437, 0.0213)[3] == pytest.approx(1000 + 1e4 * 0.04)
    assert p.point_lookup() is fast
