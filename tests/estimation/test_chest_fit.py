"""The synthetic chest fitted to a map: recovers a known chest; the defaults are the fit."""

import dataclasses

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.chest_fit import fit_synthetic_chest
from vic_drake.realdata import PhantomMapData, read_phantom_map
from vic_drake.tissue import SyntheticChestParams, SyntheticChestPhantom


def _map_of(params: SyntheticChestParams) -> PhantomMapData:
    """A chest rasterised like the measured map (1 mm grid, same footprint)."""
    x = np.linspace(-0.1587, 0.0423, 202)
    y = np.linspace(-0.4145, -0.3125, 103)
    X, Y = np.meshgrid(x, y, indexing="ij")
    s = SyntheticChestPhantom(params).sample(X, Y)
    return PhantomMapData(
        x_m=x, y_m=y, z_m=s.surface_z_m - 0.0025, kappa=s.kappa, lam=s.lam
    )


def test_the_fit_recovers_a_known_chest():
    truth = dataclasses.replace(
        SyntheticChestParams(),
        kappa_texture=0.0,
        rib_offsets_x_m=(-0.05, -0.012, 0.03, 0.07),
        rib_scales=(1.2, 1.0, 0.9, 1.0),
        muscle_rib_index=3,
        muscle_factor=0.3,
        lam_exponent=1.5,
        lam_ref=40000.0,
    )
    fit = fit_synthetic_chest(_map_of(truth))
    got = fit.params
    assert got.muscle_rib_index == 3
    np.testing.assert_allclose(got.rib_offsets_x_m, truth.rib_offsets_x_m, atol=5e-4)
    np.testing.assert_allclose(got.muscle_factor, 0.3, rtol=0.05)
    np.testing.assert_allclose(got.rib_sigma_m, truth.rib_sigma_m, rtol=0.05)
    np.testing.assert_allclose(got.kappa_soft, truth.kappa_soft, rtol=0.03)
    np.testing.assert_allclose(got.kappa_rib - got.kappa_soft,
                               truth.kappa_rib - truth.kappa_soft, rtol=0.05)  # fmt: skip
    np.testing.assert_allclose(got.rib_tilt, truth.rib_tilt, atol=0.02)
    # lambda is an exact power law of kappa here: recovered to rounding.
    np.testing.assert_allclose(got.lam_exponent, 1.5, rtol=1e-9)
    ref = 40000.0 * (got.kappa_ref / truth.kappa_ref) ** 1.5
    np.testing.assert_allclose(got.lam_ref, ref, rtol=1e-9)
    # The surface model is the phantom's own: recovered to a micrometre.
    assert fit.diagnostics["surface_rms_m"] < 1e-6
    assert got.kappa_texture < 0.01


def test_bad_options_are_clear_errors():
    m = _map_of(SyntheticChestParams())
    with pytest.raises(VicDrakeError, match="band_m"):
        fit_synthetic_chest(m, band_m=0.0)
    with pytest.raises(VicDrakeError, match="scan line"):
        fit_synthetic_chest(
            m, base=dataclasses.replace(SyntheticChestParams(), center_y_m=-0.2)
        )
    flat = dataclasses.replace(m, kappa=np.full_like(m.kappa, 5000.0))
    with pytest.raises(VicDrakeError, match="rib"):
        fit_synthetic_chest(flat)


@pytest.mark.realdata
def test_the_default_chest_is_the_fit_of_the_measured_map(data_dir):
    """SyntheticChestParams' defaults are this fit, rounded (docs: the command)."""
    measured = read_phantom_map(data_dir / "phantom_map")
    fit = fit_synthetic_chest(measured)
    default = SyntheticChestParams()
    for field in dataclasses.fields(default):
        got, want = getattr(fit.params, field.name), getattr(default, field.name)
        np.testing.assert_allclose(got, want, rtol=2e-3, atol=1e-4, err_msg=field.name)
    # The twin's surface along the scan line is within 1 mm RMS of the map's.
    assert fit.diagnostics["surface_rms_scan_line_m"] < 1e-3
