"""The real surface against the map: first contact from free space, the controller's map."""

import numpy as np
import pytest

from tests.analysis.scans import make_scan
from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.surface_offset import (
    controller_map_offset,
    first_contact_offset,
)
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import read_bag
from vic_drake.tissue import hunt_crossley_force
from vic_drake.tissue.phantom import GridPhantom, load_phantom

KAPPA, LAM, BETA, MAP_Z = 4000.0, 40000.0, 1.35, 0.1


def _flat_map() -> GridPhantom:
    xs, ys = np.linspace(-0.2, 0.1, 31), np.linspace(-0.45, -0.28, 18)
    full = np.ones((31, 18))
    return GridPhantom(
        x_m=xs, y_m=ys, z_m=MAP_Z * full, kappa=KAPPA * full, lam=LAM * full, beta=BETA
    )


def _approach(offset_m, *, start_above_m=0.010, bias_N=-0.2, noise_N=0.05, seed=0):
    """A tip settling from free space into tissue whose surface is the map's
    plus ``offset_m`` (Hunt-Crossley with its viscous term, sensor bias and
    noise); it meets the surface at about 8 mm/s and decelerates."""
    t = np.arange(0.0, 3.0, 0.002)
    surface = MAP_Z + offset_m
    z_end = surface - 0.008
    z0 = surface + start_above_m
    z = z_end + (z0 - z_end) * np.exp(-t / ((z0 - z_end) / 0.0137))
    eps = surface - z
    f = hunt_crossley_force(
        eps, np.gradient(eps, t), KAPPA, LAM, BETA, clip_tension=True
    )
    f = f + bias_N + np.random.default_rng(seed).normal(0.0, noise_N, t.size)
    return make_scan(t, f, x_m=0.03, y_m=-0.36, z_m=z)


@pytest.mark.parametrize("offset_mm", [-2.0, 0.0, 1.5, 4.0])
def test_first_contact_recovers_a_known_offset(offset_mm):
    found = first_contact_offset(_approach(offset_mm * 1e-3), _flat_map())
    assert found is not None
    assert 1e3 * found.offset_m == pytest.approx(offset_mm, abs=0.1)
    assert found.surface_z_m == pytest.approx(MAP_Z + offset_mm * 1e-3, abs=1e-4)
    assert found.bias_N == pytest.approx(-0.2, abs=0.02)
    assert 0 < found.sigma_m < 1e-4 and found.samples >= 10


def test_first_contact_needs_a_free_space_approach():
    phantom = _flat_map()
    # Already pressing when the record starts (the 9-column logs).
    pressed = _approach(0.0, start_above_m=-0.002)
    assert first_contact_offset(pressed, phantom) is None
    # Never touching.
    t = np.arange(0.0, 2.0, 0.002)
    free = make_scan(t, np.zeros(t.size), x_m=0.0, y_m=-0.36, z_m=MAP_Z + 0.01)
    assert first_contact_offset(free, phantom) is None
    with pytest.raises(VicDrakeError, match="high_N"):
        first_contact_offset(_approach(0.0), phantom, high_N=0.1)


def test_controller_map_offset_reads_the_controllers_surface():
    phantom = _flat_map()
    scan = _approach(0.0)
    assert controller_map_offset(scan, phantom) is None  # no controller surface
    scan["surface_z_m"] = MAP_Z + 0.0015
    assert controller_map_offset(scan, phantom) == pytest.approx(0.0015, abs=1e-12)


VS_LOGS = ("test_tracking5", "test_nardi_matForce_lowR")
SCAN_LOGS = ("test_compliance_control400", "test_force_control")


@pytest.mark.realdata
def test_real_logs_first_contact_and_controller_surface(data_dir):
    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    found = {}
    for name in VS_LOGS:
        real = real_to_canonical(read_bag(data_dir / "experiments" / name))
        first = first_contact_offset(real, phantom)
        assert first is not None and first.sigma_m < 1e-4
        found[name] = first.offset_m
        # The real controller's map was the published one 1.5 mm higher.
        assert controller_map_offset(real, phantom) == pytest.approx(
            1.5e-3, abs=0.05e-3
        )
        # A log edited to sit 1 mm higher has its surface 1 mm higher.
        raised = real.copy()
        raised["z_m"] += 1e-3
        assert first_contact_offset(raised, phantom).offset_m == pytest.approx(
            first.offset_m + 1e-3, abs=1e-6
        )
    assert 1e3 * found["test_tracking5"] == pytest.approx(2.89, abs=0.05)
    assert 1e3 * found["test_nardi_matForce_lowR"] == pytest.approx(4.61, abs=0.05)
    for name in SCAN_LOGS:  # these start in contact
        real = real_to_canonical(read_bag(data_dir / "experiments" / name))
        assert first_contact_offset(real, phantom) is None
        assert controller_map_offset(real, phantom) is None
