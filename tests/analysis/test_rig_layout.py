"""The rig layouts of a simulated scan: tick alignment, signs, derived columns."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.analysis.columns import CANONICAL_COLUMNS
from vic_drake.analysis.rig_layout import (
    RIG_SIGNALS,
    controller_log_rows,
    scan_log_rows,
)
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import CONTROLLER_COLUMNS, SCAN_COLUMNS

SETTINGS = dict(
    stiffness_z_min_N_per_m=100.0,
    stiffness_z_max_N_per_m=1000.0,
    eps_max_m=0.008,
    tank_min_J=0.4,
    power_limit_W=0.1,
    damping_ratio=0.707,
    beta=1.35,
)


def _frames(n=6):
    rng = np.random.default_rng(3)
    df = pd.DataFrame(rng.uniform(0.1, 1.0, (n, len(CANONICAL_COLUMNS))),
                      columns=list(CANONICAL_COLUMNS))  # fmt: skip
    df["t_s"] = 0.002 * np.arange(n)
    rig = pd.DataFrame(rng.uniform(0.1, 1.0, (n, len(RIG_SIGNALS))),
                       columns=list(RIG_SIGNALS))  # fmt: skip
    rig.loc[2, "map_penetration_m"] = -0.001  # Out of the tissue at tick 1.
    return df, rig


def test_a_controller_row_holds_one_tick():
    df, rig = _frames()
    out = controller_log_rows(df, rig, **SETTINGS)
    assert tuple(out.columns) == CONTROLLER_COLUMNS and len(out) == len(df) - 1
    # Tick n: time and target at row n; what it read and computed at row n+1.
    np.testing.assert_array_equal(out["t_s"], df["t_s"][:-1])
    np.testing.assert_array_equal(out["z_d_m"], df["z_d_m"][:-1])
    np.testing.assert_array_equal(out["z_m"], rig["controller_z_m"][1:])
    np.testing.assert_array_equal(
        out["stiffness_z_N_per_m"], df["stiffness_z_N_per_m"][1:]
    )
    np.testing.assert_array_equal(out["tank_energy_J"], df["tank_energy_J"][1:])
    np.testing.assert_allclose(out["tank_delta_J"], np.diff(df["tank_energy_J"]))
    np.testing.assert_array_equal(out["force_ref_z_N"], df["force_ref_z_N"][1:])
    # The sensor's x is flipped back to the rig's sensor frame, y and z kept.
    np.testing.assert_array_equal(
        out["sensor_force_x_N"], -rig["controller_force_x_N"][1:]
    )
    np.testing.assert_array_equal(
        out["sensor_force_y_N"], rig["controller_force_y_N"][1:]
    )
    k, e = out["stiffness_z_N_per_m"], out["z_d_m"] - out["z_m"]
    np.testing.assert_allclose(
        out["force_model_z_N"], k * e - 2 * 0.707 * np.sqrt(k) * out["vz_m_per_s"]
    )
    pen, kap, lam = (
        out["penetration_m"],
        out["kappa_N_per_m_beta"],
        out["lambda_N_s_per_m_beta1"],
    )
    hc = (kap - lam * (out["vz_m_per_s"] - out["surface_velocity_m_per_s"])) * pen**1.35
    assert np.isnan(out["force_hc_N"][1])  # Out of the tissue: NaN, as on the rig.
    np.testing.assert_allclose(out["force_hc_N"].drop(1), hc.drop(1))
    assert (out["power_limit_W"] == 0.1).all() and (out["eps_max_m"] == 0.008).all()


@pytest.mark.parametrize("lag", [0, 2])
def test_a_scan_row_pairs_the_pose_with_the_force_lag_samples_later(lag):
    df, rig = _frames()
    out = scan_log_rows(df, rig, sensor_lag_samples=lag)
    assert tuple(out.columns) == SCAN_COLUMNS and len(out) == len(df) - 1 - lag
    np.testing.assert_array_equal(out["x_m"], rig["controller_x_m"][1 : 1 + len(out)])
    np.testing.assert_array_equal(
        out["force_pressing_z_N"], -rig["controller_force_z_N"][1 + lag :]
    )
    start = rig["controller_z_m"][1] + rig["map_penetration_m"][1]
    assert (out["surface_z_start_m"] == start).all() and (
        out["palpation_no"] == 0
    ).all()


def test_bad_frames_are_clear_errors():
    df, rig = _frames()
    with pytest.raises(VicDrakeError, match="rig signals lack"):
        controller_log_rows(df, rig.drop(columns="kappa_N_per_m_beta"), **SETTINGS)
    with pytest.raises(VicDrakeError, match="sampled together"):
        controller_log_rows(df, rig.iloc[:-1], **SETTINGS)
    with pytest.raises(VicDrakeError, match="at least"):
        scan_log_rows(df.iloc[:2], rig.iloc[:2], sensor_lag_samples=3)
    with pytest.raises(VicDrakeError, match="integer"):
        scan_log_rows(df, rig, sensor_lag_samples=1.5)
