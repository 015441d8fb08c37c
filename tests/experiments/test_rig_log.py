"""A simulated scan as the rig's bag: read back by our readers, replayed by replay-qp."""

from dataclasses import replace

import numpy as np
import pytest

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.control.replay import replay_bag
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.experiments.rig_log import check_bag_scenario, write_scan_bag
from vic_drake.experiments.scan_run import run_scan
from vic_drake.realdata import read_bag

#: The replay contract of issue 10: a simulated VS-VF bag through replay-qp
#: reproduces the simulated K_z to this, N/m (the same QP from the same
#: inputs: only the solver's tolerance remains).
REPLAY_KZ_TOL_N_PER_M = 1e-3


@pytest.fixture(scope="module")
def vs_vf_scan():
    """1.6 s of VS-VF starting 5 mm above the synthetic chest: ~1 s in contact."""
    from vic_drake.tissue import load_phantom

    s = synthetic_scenario("vs-vf")
    x, y, _ = s.trajectory.start_xyz_m
    surface = float(load_phantom("synthetic").surface_z(x, y))
    s = replace(s, trajectory=replace(s.trajectory, approach_z_m=surface + 0.005))
    return run_scan(s, duration_s=1.6)


def test_vs_vf_bag_reads_back_as_the_simulated_log(vs_vf_scan, tmp_path):
    df, rig = vs_vf_scan.df, vs_vf_scan.rig
    assert df["in_contact"].sum() > 100  # The QP ran in contact.
    bag = read_bag(write_scan_bag(vs_vf_scan, tmp_path / "bag"), expect="controller")
    assert bag.attrs["topic"] == "/adaptive_stiffness_data"
    back = real_to_canonical(bag)
    n = len(back)
    assert n == len(df) - 1
    # Tick n: the canonical frame logs its time, target and sensor force at
    # row n; its K, T, F_ref, F_min (state after the tick) and the plant's
    # pose it read (the plant's sampled output) at row n + 1.
    for col in (
        "t_s", "x_d_m", "y_d_m", "z_d_m",
        "force_sensor_x_N", "force_sensor_y_N", "force_sensor_z_N",
    ):  # fmt: skip
        np.testing.assert_array_equal(back[col], df[col][:n], err_msg=col)
    for col in (
        "x_m", "y_m", "z_m", "stiffness_x_N_per_m", "stiffness_y_N_per_m", "stiffness_z_N_per_m",
        "tank_energy_J", "force_ref_z_N", "force_min_z_N",
    ):  # fmt: skip
        np.testing.assert_array_equal(back[col], df[col][1:], err_msg=col)
    # The rig's penetration is the controller's (map z + offset - z).
    np.testing.assert_allclose(back["penetration_m"], rig["map_penetration_m"][1:],
                               rtol=0, atol=1e-15)  # fmt: skip
    np.testing.assert_allclose(
        back["surface_z_m"], (rig["map_penetration_m"] + rig["controller_z_m"])[1:],
        rtol=0, atol=1e-15,
    )  # fmt: skip
    assert np.isfinite(bag["kappa_N_per_m_beta"]).all()


def test_replay_qp_reproduces_the_simulated_stiffness(vs_vf_scan, tmp_path):
    path = write_scan_bag(vs_vf_scan, tmp_path / "bag")
    r = vs_vf_scan.scenario.controller.qp.r_weight[2]
    result = replay_bag(path, r_weight=r, solver="osqp")
    summary = result.summary()
    assert summary["failures"] == 0 and summary["ticks"] == len(vs_vf_scan.df) - 2
    assert summary["kz_abs_err_max"] <= REPLAY_KZ_TOL_N_PER_M
    assert summary["tank_abs_err_max_J"] <= 1e-9
    # Not a trivially flat record: the QP moved K_z in contact.
    assert np.ptp(result.stiffness_logged_N_per_m[:, 2]) > 100.0


def test_cs_bag_is_the_9_column_scan_log(tmp_path):
    result = run_scan(synthetic_scenario("cs"), duration_s=0.1)
    bag = read_bag(write_scan_bag(result, tmp_path / "bag"), expect="scan")
    assert bag.attrs["topic"] == "/data_control" and len(bag) == len(result.df) - 1
    back = real_to_canonical(bag)
    np.testing.assert_array_equal(back["z_m"], result.df["z_m"][1:])
    np.testing.assert_array_equal(
        back["force_sensor_z_N"], result.df["force_sensor_z_N"][:-1]
    )


def test_a_log_that_is_not_one_row_per_tick_cannot_be_a_bag():
    s = synthetic_scenario("vs-vf")
    s = replace(s, logging=replace(s.logging, period_s=0.01))
    with pytest.raises(VicDrakeError, match="one row per controller tick"):
        check_bag_scenario(s)


def test_a_simulated_palpation_bag_reads_back_as_the_record(tmp_path):
    from vic_drake.estimation.palpation import PalpationData
    from vic_drake.experiments import CampaignParams, simulate_palpations
    from vic_drake.experiments.rig_log import write_palpation_bag
    from vic_drake.systems.indenter import PalpationParams

    params = CampaignParams(palpation=PalpationParams(duration_s=1.0))
    (record,) = simulate_palpations(
        [0.0], [0.0], surface_z=[0.1], kappa=[2.0e5], lam=[5.0], beta=1.35,
        params=params, seed=4,
    )  # fmt: skip
    bag = read_bag(write_palpation_bag(record, tmp_path / "bag", surface_z_m=0.1))
    assert bag.attrs["layout"] == "palpation"
    data = PalpationData.from_frame(bag)
    np.testing.assert_allclose(data.t_s, record.t_s, atol=1e-9)
    np.testing.assert_array_equal(data.z_m, record.z_m)
    np.testing.assert_array_equal(data.force_N, record.force_N)  # Pressing: > 0.
    assert data.surface_z_m == 0.1 and record.force_N.max() > 1.0
    with pytest.raises(VicDrakeError, match="2 samples or more"):
        one = replace(record, t_s=record.t_s[:1], z_m=record.z_m[:1])
        write_palpation_bag(one, tmp_path / "b", surface_z_m=0.1)
