"""The one rib detector, on profiles with known ribs."""

import numpy as np
import pytest

from vic_drake.analysis.ribs import RIB_MIN_PROMINENCE, find_ribs, rib_prominences
from vic_drake.errors import VicDrakeError


def _profile(x, centres, amplitudes, base=4000.0, width=0.004):
    p = np.full_like(x, base)
    for c, a in zip(centres, amplitudes):
        p += a * np.exp(-0.5 * ((x - c) / width) ** 2)
    return p


def test_find_ribs_finds_gaussian_bands_above_the_prominence_rule():
    x = np.linspace(-0.15, 0.04, 381)
    centres = [-0.12, -0.08, -0.04, 0.0]
    p = _profile(x, centres, [3000, 2500, 600, 2800])
    ribs = find_ribs(x, p)
    np.testing.assert_allclose(ribs.position_m, centres, atol=6e-4)
    assert ribs.relative.min() >= RIB_MIN_PROMINENCE


def test_find_ribs_ignores_texture_below_the_rule_and_flat_profiles():
    x = np.linspace(-0.15, 0.04, 381)
    bump = 0.5 * RIB_MIN_PROMINENCE * 4000.0
    assert find_ribs(x, _profile(x, [-0.05], [bump])).position_m.size == 0
    assert find_ribs(x, np.full_like(x, 5.0)).position_m.size == 0
    with pytest.raises(VicDrakeError, match="same length"):
        find_ribs(x, x[:-1])


def test_map_summary_uses_the_same_detector():
    x = np.linspace(-0.15, 0.04, 191)
    y = np.linspace(-0.41, -0.31, 11)
    prof = _profile(x, [-0.12, -0.08, -0.04, 0.0], [3000, 2500, 600, 2800])
    kappa = np.repeat(prof[:, None], y.size, axis=1)
    d = rib_prominences(x, y, kappa)
    ribs = find_ribs(x, prof, reference=float(np.median(kappa)))
    assert d["rib_position_m"] == pytest.approx(ribs.position_m.tolist())
    assert d["n_strong"] == 3 and d["n_weak"] == 1
