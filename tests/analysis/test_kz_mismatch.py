"""Diagnostics of compare-real's K_z correlation: where it is lost, and which input carries it."""

import numpy as np
import pytest

from tests.analysis.scans import Z_SCAN_M, make_scan
from tests.tissue.phantom.planes import plane_phantom
from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.kz_mismatch import (
    kz_deficit_by_bin,
    kz_input_swap,
    tip_height_components,
)
from vic_drake.analysis.phantom_motion import penetration_m
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import read_bag

T = np.arange(0.0, 10.0, 0.01)


def _vs_scan(t, k, *, force_ref=-7.0, z=Z_SCAN_M + 0.012):
    return make_scan(
        t,
        np.full(len(t), 7.0),
        z_m=z,
        force_ref_z_N=force_ref,
        force_min_z_N=-9.0,
        stiffness_z_N_per_m=k,
    )


def test_the_deficit_sits_in_the_bin_where_the_stiffness_differs():
    """Sim K_z off by 150 N/m over 6-7 s only: that second holds most of
    1 - r, the shares add up to 1 and the total is 2 n (1 - r)."""
    k_real = 500 + 100 * np.sin(T)
    k_sim = k_real + np.where((T >= 6) & (T < 7), 150.0, 0.0)
    real, sim = _vs_scan(T, k_real), _vs_scan(T, k_sim)
    bins = kz_deficit_by_bin(sim, real)
    assert bins["deficit_share"].sum() == pytest.approx(1.0)
    worst = bins.loc[bins["deficit_share"].idxmax()]
    assert worst["t0_s"] == 6.0
    assert worst["deficit_share"] > 0.8
    assert worst["k_sim"] - worst["k_real"] == pytest.approx(150.0)
    window = T >= 1.0  # scan_window: first contact + 1 s
    r = np.corrcoef(k_real[window], k_sim[window])[0, 1]
    assert bins.attrs["kz_corr"] == pytest.approx(r)
    assert bins["samples"].sum() == window.sum()


def test_the_time_offset_is_applied_and_the_force_row_flagged():
    """The simulated record 0.2 s early, shifted back: r = 1. A reference
    below F_min in one second is flagged there only."""
    k = 500 + 100 * np.sin(T)
    f_ref = np.where((T >= 3) & (T < 4), -10.0, -7.0)
    real = _vs_scan(T, k)
    sim = _vs_scan(T - 0.2, k, force_ref=f_ref)
    bins = kz_deficit_by_bin(sim, real, time_offset_s=0.2)
    assert bins.attrs["kz_corr"] == pytest.approx(1.0, abs=1e-12)
    flagged = bins.set_index("t0_s")["f_min_binds_sim"]
    # Rows at sim 2.8-3.8 s land on 3-4 s (unshifted: 0.2 / 0.8 in bins 2 / 3).
    assert flagged[3.0] == 1.0
    assert flagged[2.0] == 0.0
    assert (bins["deficit_share"] == 0).all()  # r = 1: nothing lost anywhere
    assert (bins["f_min_binds_real"] == 0).all()


def test_bad_bins_and_constant_stiffness_are_errors():
    real = _vs_scan(T, 500 + 100 * np.sin(T))
    with pytest.raises(VicDrakeError, match="bin_s"):
        kz_deficit_by_bin(real, real, bin_s=0.0)
    with pytest.raises(VicDrakeError, match="varying K_z"):
        kz_deficit_by_bin(_vs_scan(T, np.full(len(T), 500.0)), real)


def _on_plane(t, x, force, surface_offset_m, phantom):
    """A scan on a plane phantom whose tissue lies surface_offset_m above
    the map, with its tip height from the force inverted the way the
    diagnostic inverts it (so the apparent surface is exact)."""
    y = np.full(len(t), 0.02)
    df = make_scan(t, force, x_m=x, y_m=y)
    pen = penetration_m(df, phantom)
    df["z_m"] = phantom.surface_z(x, y) + surface_offset_m - pen
    return df, pen


def test_tip_height_split_into_lateral_surface_and_penetration():
    """Sim tip 2 mm behind on a 0.2 slope, its tissue 1 mm above the map
    against the real 3 mm, pressing 6 N against 5 N: the three parts come
    back, and they add up to the height difference."""
    phantom = plane_phantom()
    x_real = 0.09 - 0.008 * T  # on the plane (x in 0-0.1 m) throughout
    real, pen_real = _on_plane(T, x_real, np.full(len(T), 5.0), 0.003, phantom)
    sim, pen_sim = _on_plane(T, x_real + 0.002, np.full(len(T), 6.0), 0.001, phantom)
    parts = tip_height_components(sim, real, phantom)
    assert len(parts) == (T >= 1.0).sum()
    np.testing.assert_allclose(parts["lateral_m"], 0.2 * 0.002, atol=1e-9)
    np.testing.assert_allclose(parts["surface_m"], -0.002, atol=1e-9)
    np.testing.assert_allclose(parts["apparent_real_m"], 0.003, atol=1e-9)
    window = T >= 1.0
    np.testing.assert_allclose(
        parts["penetration_m"], (pen_sim - pen_real)[window], atol=1e-9
    )
    assert (parts["penetration_m"] > 0).all()  # 6 N presses deeper than 5 N
    np.testing.assert_allclose(
        parts["dz_m"],
        parts["lateral_m"] + parts["surface_m"] - parts["penetration_m"],
        atol=1e-12,
    )


@pytest.fixture(scope="module")
def nardi(data_dir):
    return read_bag(data_dir / "experiments" / "test_nardi_matForce_lowR")


@pytest.mark.realdata
def test_swapping_the_tip_height_carries_the_stiffness_mismatch(nardi):
    """The VS-VF log's own inputs give back its K_z (r = 1); its tip height
    tilted by 4 mm along the scan lowers r, while the same tilt's stand-in
    for the force reference (unchanged values) does not."""
    real = real_to_canonical(nardi)
    assert kz_input_swap(nardi, real, [], r_weight=1e-5) == pytest.approx(1.0, abs=1e-9)
    t = real["t_s"].to_numpy()
    tilted = real.copy()
    tilted["z_m"] = real["z_m"] + 0.004 * (t - t[0]) / (t[-1] - t[0])
    same_refs = kz_input_swap(nardi, tilted, ["force_ref", "force_min"], r_weight=1e-5)
    assert same_refs == pytest.approx(1.0, abs=1e-9)
    assert kz_input_swap(nardi, tilted, ["z"], r_weight=1e-5) < 0.95


@pytest.mark.realdata
def test_swap_refuses_unknown_inputs_and_other_layouts(nardi):
    real = real_to_canonical(nardi)
    with pytest.raises(VicDrakeError, match="among"):
        kz_input_swap(nardi, real, ["stiffness"], r_weight=1e-5)
    with pytest.raises(VicDrakeError, match="31-column"):
        kz_input_swap(real, real, ["z"], r_weight=1e-5)
