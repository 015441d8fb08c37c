"""Scan metrics on records with known answers."""

import math

import numpy as np
import pandas as pd
import pytest

from tests.analysis.scans import make_scan
from vic_drake.analysis.contact import scan_window
from vic_drake.analysis.scan_metrics import (
    force_range_N,
    force_rmse_N,
    peak_force_N,
    penetration_stats,
    tank_min_J,
)
from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom import SyntheticChestPhantom


def test_force_rmse_and_range_against_hand_values():
    t = np.arange(0, 10, 0.002)
    f = np.where(t < 1, 0.0, 7.0 + np.sin(2 * np.pi * t))  # Contact from t = 1.
    df = make_scan(t, f, force_ref_z_N=-7.0)
    window = scan_window(df, settle_s=1.0)
    assert t[window][0] == pytest.approx(2.0, abs=0.003)
    # RMS of a unit sine over whole periods is 1/sqrt(2).
    assert force_rmse_N(df) == pytest.approx(1 / np.sqrt(2), rel=2e-3)
    lo, hi = force_range_N(df)
    assert lo == pytest.approx(6.0, abs=1e-4) and hi == pytest.approx(8.0, abs=1e-4)
    assert peak_force_N(df) == pytest.approx(8.0, abs=1e-4)


def test_tank_min_and_missing_columns():
    t = np.arange(0, 1, 0.01)
    df = make_scan(t, np.ones_like(t), tank_energy_J=0.5 - 0.1 * t)
    assert tank_min_J(df) == pytest.approx(0.401)
    with pytest.raises(VicDrakeError, match="lacks columns"):
        force_rmse_N(pd.DataFrame({"t_s": t}))


def test_penetration_stats_split_ribs_from_soft_tissue():
    phantom = SyntheticChestPhantom()
    t = np.arange(0, 20, 0.01)
    x = 0.036 - 0.01 * t
    y = np.full_like(t, -0.36)
    kappa = phantom.kappa(x, y)
    pen = np.where(kappa > 7000, 0.003, 0.008)
    df = make_scan(t, np.full_like(t, 7.0), x_m=x, y_m=y, penetration_m=pen)
    stats = penetration_stats(df, phantom)
    assert stats.rib_samples > 0 and stats.soft_samples > stats.rib_samples
    assert stats.rib_mean_m == pytest.approx(
        0.003
    ) and stats.soft_mean_m == pytest.approx(0.008)


def test_the_log_says_which_controller_has_no_reference_or_tank():
    """run_scan's logs carry their controller: CS has no force reference (its
    logged 0 would score the pressing force) and CS and CF no tank (they log
    its initial energy). A log that does not say (a rig log) and holds a zero
    reference over the window has none either."""
    t = np.arange(0, 4, 0.002)
    df = make_scan(t, np.where(t < 1, 0.0, 6.0))
    df["force_ref_z_N"], df["tank_energy_J"] = 0.0, 0.5
    assert math.isnan(force_rmse_N(df))  # No controller said; the reference is 0.
    df["force_ref_z_N"] = -5.0
    assert force_rmse_N(df) == pytest.approx(1.0)
    assert tank_min_J(df) == 0.5
    for controller, rmse_is_nan in (("cs", True), ("cf", False)):
        df.attrs["controller"] = controller
        assert math.isnan(force_rmse_N(df)) is rmse_is_nan
        assert math.isnan(tank_min_J(df))
        assert math.isnan(tank_min_J(df[t > 1.0]))  # A slice keeps it.
        assert tank_min_J(df, has_tank=True) == 0.5  # The argument decides.


def test_scan_metrics_scores_a_log_on_its_own_controllers_limits():
    """run_scan stores the controller's limits in the log: scan_metrics
    without ``limits`` uses them (CF: no tank, no penetration target; a VS-VF
    eps_d of 6 mm), and the real controller's defaults on a log without."""
    import dataclasses

    from vic_drake.analysis.claims import ScanLimits, scan_metrics
    from vic_drake.control.params import real_controller_params

    t = np.arange(0, 10, 0.002)
    force = np.where(t < 1, 0.0, 7.0)
    df = make_scan(
        t,
        force,
        force_ref_z_N=-7.0,
        force_min_z_N=-9.0,
        penetration_m=np.where(t < 1, -0.01, 0.006),
        tank_energy_J=0.5,
        tank_power_W=0.0,
    )
    plain = scan_metrics(df)  # No limits stored: the defaults (eps_d 8 mm).
    assert plain["penetration_error_off_ribs_median_m"] == pytest.approx(0.002)
    assert plain["tank_min_J"] == 0.5
    cf = df.copy()
    cf.attrs["scan_limits"] = dataclasses.asdict(
        ScanLimits.from_controller(real_controller_params("cf"))
    )
    m = scan_metrics(cf)
    assert math.isnan(m["tank_min_J"]) and math.isnan(m["tank_power_min_W"])
    assert "penetration_error_off_ribs_median_m" not in m
    assert m["penetration_off_ribs_median_m"] == pytest.approx(0.006)
    params = real_controller_params("vs-vf")
    params.reference.eps_d_m = 0.006
    vsvf = df.copy()
    vsvf.attrs["scan_limits"] = dataclasses.asdict(ScanLimits.from_controller(params))
    assert scan_metrics(vsvf)["penetration_error_off_ribs_median_m"] == pytest.approx(
        0.0
    )


def test_metrics_name_what_was_given_instead_of_a_log():
    from types import SimpleNamespace

    from vic_drake.analysis.claims import scan_metrics

    t = np.arange(0, 4, 0.002)
    df = make_scan(t, np.where(t < 1, 0.0, 6.0), force_ref_z_N=-5.0)
    result = SimpleNamespace(df=df)  # As a ScanResult holds its log.
    with pytest.raises(
        VicDrakeError, match=r"got a SimpleNamespace \(its log is result\.df\)"
    ):
        scan_metrics(result)
    with pytest.raises(VicDrakeError, match=r"its log is result\.df"):
        force_rmse_N(result)
    with pytest.raises(VicDrakeError, match=r"limits must be a ScanLimits"):
        scan_metrics(df, limits=SimpleNamespace(eps_d_m=0.008))
    with pytest.raises(VicDrakeError, match=r"one bool per row of the log \(2000\)"):
        force_rmse_N(df, mask=[True] * 10)
