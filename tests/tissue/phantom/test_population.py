"""Synthetic patients (population) and map errors (distorted phantoms)."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom import GridPhantom, SyntheticChestPhantom
from vic_drake.tissue.phantom.distorted import DistortedPhantom, with_map_errors
from vic_drake.tissue.phantom.population import (
    POPULATION_RANGES,
    patient_chest_params,
    patient_phantom,
    sample_patient,
)

X = np.linspace(-0.2, 0.08, 57)
Y = np.full_like(X, -0.36)


def test_reference_patient_is_the_reference_chest():
    ref = SyntheticChestPhantom().sample(X, Y)
    pat = patient_phantom({}).sample(X, Y)
    for a, b in zip(
        (ref.surface_z_m, ref.kappa, ref.lam), (pat.surface_z_m, pat.kappa, pat.lam)
    ):
        np.testing.assert_allclose(a, b, rtol=1e-12)


def test_patient_factors_act_as_documented():
    ref = SyntheticChestPhantom().sample(X, Y)
    stiff = patient_phantom({"kappa_scale": 1.2, "lam_scale": 0.8}).sample(X, Y)
    np.testing.assert_allclose(stiff.kappa, 1.2 * ref.kappa, rtol=1e-9)
    np.testing.assert_allclose(stiff.lam, 0.8 * ref.lam, rtol=1e-9)
    thick = patient_phantom({"soft_tissue_offset_m": 0.003}).sample(X, Y)
    np.testing.assert_allclose(thick.surface_z_m, ref.surface_z_m + 0.003, atol=1e-12)
    deep = patient_chest_params({"rib_depth_m": 0.02})
    base = patient_chest_params({})
    assert deep.kappa_rib - deep.kappa_soft == pytest.approx(
        0.5 * (base.kappa_rib - base.kappa_soft)
    )
    assert deep.rib_sigma_m > base.rib_sigma_m


def test_sample_patient_is_seeded_and_inside_the_ranges():
    a, b = sample_patient(3), sample_patient(3)
    assert a == b and a != sample_patient(4)
    for seed in range(50):
        p = sample_patient(seed)
        for name, (_, low, high) in POPULATION_RANGES.items():
            assert low <= p[name] <= high
        patient_phantom(p)  # Every draw makes a valid chest.
    with pytest.raises(VicDrakeError, match="rib_depth_m"):
        patient_phantom({"rib_depth_m": 0.5})
    with pytest.raises(VicDrakeError, match="unknown factor"):
        patient_phantom({"ribs": 3})


def test_map_errors_scale_offset_and_shift_the_map():
    chest = SyntheticChestPhantom()
    assert with_map_errors(chest) is chest
    wrong = with_map_errors(
        chest, kappa_scale=1.3, lam_scale=0.7, surface_offset_m=0.002, shift_x_m=0.01
    )
    assert isinstance(wrong, DistortedPhantom)
    s, r = wrong.sample(X, Y), chest.sample(X - 0.01, Y)
    np.testing.assert_allclose(s.kappa, 1.3 * r.kappa)
    np.testing.assert_allclose(s.lam, 0.7 * r.lam)
    np.testing.assert_allclose(s.surface_z_m, r.surface_z_m + 0.002)


def test_map_errors_keep_a_grid_a_grid_with_its_lookup():
    x, y = np.linspace(0, 0.1, 11), np.linspace(0, 0.05, 6)
    z = np.add.outer(x, y)
    grid = GridPhantom(
        x_m=x,
        y_m=y,
        z_m=z,
        kappa=np.full_like(z, 2000.0),
        lam=np.full_like(z, 1e4),
        lookup="nearest",
        surface_offset_m=0.0025,
    )
    wrong = with_map_errors(
        grid, kappa_scale=0.7, surface_offset_m=-0.001, shift_y_m=0.01
    )
    assert isinstance(wrong, GridPhantom) and wrong.lookup == "nearest"
    s, r = wrong.sample(0.05, 0.03), grid.sample(0.05, 0.02)
    assert s.kappa == pytest.approx(0.7 * 2000.0)
    assert s.surface_z_m == pytest.approx(r.surface_z_m - 0.001)
