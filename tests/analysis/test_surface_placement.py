"""The placement plane of a resting phantom, read from the in-contact surface."""

import numpy as np
import pytest

from tests.analysis.scans import make_scan
from vic_drake.analysis.surface_placement import (
    MIN_SPAN_M,
    apparent_surface_m,
    fit_surface_placement,
)
from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom import GridPhantom
from vic_drake.tissue.relaxation import (
    DEFAULT_RELAXATION,
    relaxation_history,
    relaxation_input,
    relaxing_hunt_crossley_force,
)

BETA = 1.35
DT = 0.002
X0, Y0 = -0.055, -0.355


def _map() -> GridPhantom:
    """A map with a sloped, curved surface and kappa, lambda varying along x."""
    xs, ys = np.linspace(-0.2, 0.1, 61), np.linspace(-0.45, -0.28, 35)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return GridPhantom(
        x_m=xs,
        y_m=ys,
        z_m=0.1 + 0.05 * gx + 0.3 * gx**2 - 0.1 * (gy + 0.36),
        kappa=3300.0 * (1.0 + 2.0 * gx),
        lam=32000.0 * (1.0 - gx),
        beta=BETA,
    )


def _scan(phantom, offset_m, slope_m_per_m, *, along="x", relax=True, seed=0):
    """A tip sliding 18 cm over tissue whose surface is the map's plus the plane
    ``offset_m + slope (p - p0) . track``, pressed 6-10 mm (force steps like
    VS-VF's), on relaxing Hunt-Crossley tissue with its viscous term;
    0.5 s of free space first; sensor noise 0.05 N."""
    t = np.arange(0.0, 20.0, DT)
    s = np.clip((t - 1.0) / 18.0, 0.0, 1.0)  # 0 -> 1 along the track
    pos = 0.035 - 0.18 * s
    drift = 0.003 * np.sin(7.0 * s)  # a few mm across the track
    if along == "x":
        x, y = pos, Y0 + drift
        track = x - X0
    else:
        x, y = X0 + drift, -0.31 - 0.18 * s
        track = y - (-0.40)
    surface = phantom.surface_z(x, y) + offset_m + slope_m_per_m * track
    eps = np.clip((t - 0.5) / 0.5, 0.0, 1.0) * (0.008 + 0.002 * np.sign(np.sin(t)))
    eps = np.convolve(eps, np.ones(50) / 50, "same")  # steps over 0.1 s
    eps[t < 0.5] = -0.002
    z = surface - eps
    eps_dot = np.gradient(eps, t)
    u = relaxation_input(eps, BETA)
    if relax:
        g = DEFAULT_RELAXATION.fractions
        states = relaxation_history(t, u, DEFAULT_RELAXATION.time_constants_s)
    else:
        g, states = (), np.zeros((t.size, 0))
    f = relaxing_hunt_crossley_force(
        eps, eps_dot, phantom.kappa(x, y), phantom.lam(x, y), BETA, states, g,
        clip_tension=True,
    )  # fmt: skip
    f = f + np.random.default_rng(seed).normal(0.0, 0.05, t.size)
    return make_scan(t, f, x_m=x, y_m=y, z_m=z)


@pytest.mark.parametrize("slope", [-0.020, 0.0, 0.015])
@pytest.mark.parametrize("offset", [-0.002, 0.003])
def test_the_plane_is_read_back(slope, offset):
    phantom = _map()
    found = fit_surface_placement(_scan(phantom, offset, slope), phantom)
    assert found is not None
    assert found.direction[0] == pytest.approx(1.0, abs=1e-3)
    assert 1e3 * found.slope_m_per_m == pytest.approx(1e3 * slope, abs=0.3)
    true_at_origin = offset + slope * (found.x0_m - X0)
    assert 1e3 * found.offset_m == pytest.approx(1e3 * true_at_origin, abs=0.03)
    x = np.linspace(-0.14, 0.03, 9)
    np.testing.assert_allclose(
        found.offset_at(x, Y0), offset + slope * (x - X0), atol=1e-4
    )
    assert found.bins >= 15 and found.span_m > 0.15
    assert found.start_m < 0.0 < found.start_m + found.span_m  # the origin inside
    assert 0 < found.slope_sigma_m < 1e-3 and 0 < found.offset_sigma_m < 1e-4


def test_a_track_along_y_is_read_along_y():
    phantom = _map()
    found = fit_surface_placement(_scan(phantom, 0.002, 0.01, along="y"), phantom)
    assert abs(found.direction[1]) == pytest.approx(1.0, abs=1e-3)
    gx, gy = found.gradient
    assert gx == pytest.approx(0.0, abs=3e-4) and gy == pytest.approx(0.01, abs=3e-4)


def test_the_relaxation_correction_is_needed():
    """Read through plain Hunt-Crossley, the relaxing tissue's force falls
    along the scan and the surface seems to sink along the track."""
    phantom = _map()
    scan = _scan(phantom, 0.003, 0.0)
    plain = fit_surface_placement(scan, phantom, relaxation=None)
    assert 1e3 * plain.slope_m_per_m > 0.8  # the end (-x) reads low
    # On plain Hunt-Crossley tissue the relaxation is left out.
    hc = fit_surface_placement(
        _scan(phantom, 0.003, 0.0, relax=False), phantom, relaxation=None
    )
    assert 1e3 * hc.slope_m_per_m == pytest.approx(0.0, abs=0.3)


def test_the_apparent_surface_is_the_true_one_in_contact():
    phantom = _map()
    scan = _scan(phantom, 0.003, 0.01)
    surface = apparent_surface_m(scan, phantom)
    inside = np.isfinite(surface)
    assert not inside[: int(0.5 / DT)].any()  # free space: NaN
    x = scan["x_m"].to_numpy()
    t = scan["t_s"].to_numpy()
    late = inside & (t > 1.5) & (t < 19.5)
    truth = 0.003 + 0.01 * (x - X0)
    # The force noise (0.05 N) is 0.06 mm of penetration at 8 mm.
    assert np.median(np.abs(surface[late] - truth[late])) < 1e-4


def test_a_local_bump_hardly_tilts_the_plane():
    """1 cm of the track where the force says the surface is 5 mm higher
    (a rib, a sensor fault): the Huber line on the bins' medians gives it
    little weight."""
    phantom = _map()
    scan = _scan(phantom, 0.003, 0.0)
    x = scan["x_m"].to_numpy()
    bump = (x > 0.0) & (x < 0.01)
    scan.loc[bump, "z_m"] += 0.005
    found = fit_surface_placement(scan, phantom)
    assert abs(1e3 * found.slope_m_per_m) < 1.0
    design = np.c_[np.ones(bump.size), x]
    # Least squares on the samples would tilt it by more.
    ols = np.linalg.lstsq(design, 0.003 + np.where(bump, 0.005, 0.0), rcond=None)[0]
    assert abs(1e3 * ols[1]) > 2.0


def test_no_plane_without_enough_track():
    phantom = _map()
    scan = _scan(phantom, 0.003, 0.0)
    t = scan["t_s"].to_numpy()
    short = (t > 2.0) & (t < 2.0 + 18.0 * 0.8 * MIN_SPAN_M / 0.18)
    assert fit_surface_placement(scan, phantom, window=short) is None
    assert fit_surface_placement(scan, phantom, window=np.zeros(len(t), bool)) is None
    with pytest.raises(VicDrakeError, match="window"):
        fit_surface_placement(scan, phantom, window=np.ones(3, bool))
