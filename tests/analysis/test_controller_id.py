"""The controller of a real scan log and its settings, from the signals alone."""

import shutil

import numpy as np
import pytest

from tests.analysis.qp_logs import with_qp_stiffness
from vic_drake.analysis.controller_id import (
    MIN_CONTACT_SAMPLES,
    identify_controller,
    scan_law_scores,
    vs_law_scores,
)
from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTACT_THRESHOLD_N
from vic_drake.realdata import read_bag

#: log -> (controller, setting, expected value, relative tolerance). The
#: settings of the data README: CS 400 N/m, CF 7 N (the CF reference is not
#: logged; its logged force averages 7.1 N), VS-CF 7 N.
SHARED_LOGS = {
    "test_compliance_control400": ("cs", "stiffness_N_per_m", 400.0, 0.1),
    "test_compliance_control400_dist": ("cs", "stiffness_N_per_m", 400.0, 0.1),
    "test_force_control": ("cf", "force_ref_N", 7.0, 0.05),
    "test_force_control_dist": ("cf", "force_ref_N", 7.0, 0.05),
    "test_tracking5": ("vs-cf", "force_ref_N", 7.0, 1e-9),
    "test_nardi_matForce_lowR": ("vs-vf", "force_min_z_N", -9.0, 1e-9),
}
#: The QP weight R the README gives each 31-column log.
SHARED_R = {"test_tracking5": 0.1, "test_nardi_matForce_lowR": 1e-5}


@pytest.fixture(scope="module")
def logs(data_dir):
    return {name: read_bag(data_dir / "experiments" / name) for name in SHARED_LOGS}


def _contact_runs(real):
    """(start, stop) row ranges of the runs longer than 100 samples where the
    sensor reads contact and the logged F_ref,z is on."""
    on = (real["sensor_force_z_N"].to_numpy() < -CONTACT_THRESHOLD_N) & (
        real["force_ref_z_N"].to_numpy() != 0.0
    )
    edges = np.flatnonzero(np.diff(np.r_[0, on.astype(int), 0]))
    return [(a, b) for a, b in zip(edges[::2], edges[1::2]) if b - a > 100]


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(SHARED_LOGS))
def test_every_shared_log_is_identified_under_a_neutral_name(name, data_dir, tmp_path):
    """Each shared log, copied to a folder whose name says nothing, gives its
    controller and setting (and R on the 31-column logs)."""
    neutral = tmp_path / "scan_log"
    shutil.copytree(data_dir / "experiments" / name, neutral)
    got = identify_controller(read_bag(neutral))
    kind, key, value, rel = SHARED_LOGS[name]
    assert got.controller == kind and not got.given
    assert got.settings[key] == pytest.approx(value, rel=rel)
    if name in SHARED_R:
        assert got.settings["r_weight"] == pytest.approx(SHARED_R[name], rel=1e-6)
        assert got.evidence["replay_kz_err_max"] < 1e-6
        assert got.evidence[f"{kind.replace('-', '_')}_explained"] == 1.0
    if kind == "vs-vf":
        assert got.settings["eps_d_m"] == pytest.approx(0.008, rel=1e-9)
    assert kind in got.summary() and "identified" in got.summary()


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(SHARED_R))
def test_zero_references_at_the_contact_edges_change_nothing(name, logs):
    """F_ref,z = 0 in the first and last 25 samples of every long contact run
    (the controller's contact flag lagging the sensor's): same class, same
    settings; the zero samples are counted, not scored."""
    real = logs[name].copy()
    ref = real["force_ref_z_N"].to_numpy(copy=True)
    runs = _contact_runs(real)
    for start, stop in runs:
        ref[start : start + 25] = 0.0
        ref[stop - 25 : stop] = 0.0
    real["force_ref_z_N"] = ref
    before = identify_controller(logs[name], r_weight=1.0)
    got = identify_controller(real, r_weight=1.0)
    assert got.controller == before.controller
    assert got.evidence["reference_off_samples"] == 50 * len(runs)
    for key in ("force_ref_N", "eps_d_m", "force_min_z_N"):
        if key in before.settings:
            assert got.settings[key] == pytest.approx(before.settings[key], rel=1e-9)


@pytest.mark.realdata
def test_a_few_zero_references_inside_contact_keep_vs_cf(logs):
    """The failure of the spread test: a constant-force log with F_ref,z = 0
    in five samples where the sensor reads contact is still VS-CF."""
    real = logs["test_tracking5"].copy()
    ref = real["force_ref_z_N"].to_numpy(copy=True)
    contact = real["sensor_force_z_N"].to_numpy() < -CONTACT_THRESHOLD_N
    rows = np.flatnonzero(contact)[[100, 2000, 4000, 6000, 8000]]
    ref[rows] = 0.0
    real["force_ref_z_N"] = ref
    assert np.ptp(ref[contact]) > 0.5  # What the spread test took for VS-VF.
    got = identify_controller(real)
    assert got.controller == "vs-cf"
    assert got.settings["force_ref_N"] == pytest.approx(7.0)
    assert got.evidence["reference_off_samples"] == 5
    assert got.settings["r_weight"] == pytest.approx(0.1, rel=1e-6)


@pytest.mark.realdata
def test_vs_cf_log_at_8_N(logs):
    """A VS-CF log rescaled to an 8 N reference (its stiffness recomputed by
    the QP at R = 0.1 from the new reference) reads as VS-CF at 8 N."""
    real = logs["test_tracking5"].copy()
    real["force_ref_z_N"] = real["force_ref_z_N"] * (8.0 / 7.0)
    real = with_qp_stiffness(real, 0.1)
    got = identify_controller(real)
    assert got.controller == "vs-cf"
    assert got.settings["force_ref_N"] == pytest.approx(8.0, rel=1e-9)
    assert got.settings["r_weight"] == pytest.approx(0.1, rel=1e-6)


@pytest.mark.realdata
def test_half_constant_half_map_reference_is_ambiguous(logs):
    """F_ref,z constant in the first half of the contact samples and the map
    law in the second: neither law wins by the margin."""
    real = logs["test_nardi_matForce_lowR"].copy()
    ref = real["force_ref_z_N"].to_numpy(copy=True)
    on = np.flatnonzero(ref != 0.0)
    ref[on[: on.size // 2]] = -7.0
    real["force_ref_z_N"] = ref
    s = vs_law_scores(real)
    assert abs(s["vs_cf_explained"] - s["vs_vf_explained"]) < 0.1
    with pytest.raises(VicDrakeError, match="cannot tell.*--controller"):
        identify_controller(real)


@pytest.mark.realdata
def test_f_min_contradicting_f_ref_is_an_error(logs):
    """A constant F_ref,z (VS-CF) with F_min,z held at -9 N in contact (VS-VF)."""
    real = logs["test_tracking5"].copy()
    f_min = real["force_min_z_N"].to_numpy(copy=True)
    f_min[real["force_ref_z_N"].to_numpy() != 0.0] = -9.0
    real["force_min_z_N"] = f_min
    with pytest.raises(VicDrakeError, match="contradictory.*--controller"):
        identify_controller(real)


@pytest.mark.realdata
@pytest.mark.parametrize("name", ["test_tracking5", "test_force_control"])
def test_too_little_contact_is_an_error(name, logs):
    """A log cut 100 samples after its first contact cannot be told; with
    the controller given, its settings are still read."""
    real = logs[name]
    if real.attrs["layout"] == "controller":
        contact = real["sensor_force_z_N"].to_numpy() < -CONTACT_THRESHOLD_N
    else:
        contact = real["force_pressing_z_N"].to_numpy() > CONTACT_THRESHOLD_N
    first = int(np.argmax(contact))
    short = real.iloc[: first + 100 + 28].copy()
    short.attrs.update(real.attrs)
    with pytest.raises(
        VicDrakeError, match=f"{MIN_CONTACT_SAMPLES} needed.*--controller"
    ):
        identify_controller(short)
    if name == "test_tracking5":
        got = identify_controller(short, controller="vs-cf", r_weight=0.1)
        assert got.given and got.settings["force_ref_N"] == pytest.approx(7.0)


@pytest.mark.realdata
def test_scan_log_with_a_constant_error_is_ambiguous(logs):
    """A 9-column log whose tip keeps one height above its target: f = K e
    and f = f_ref fit alike, and the identification says so."""
    real = logs["test_compliance_control400"].copy()
    rng = np.random.default_rng(0)
    real["z_m"] = real["z_target_m"] + 0.018 + 1e-6 * rng.standard_normal(len(real))
    s = scan_law_scores(real)
    assert abs(s["cs_explained"] - s["cf_explained"]) < 0.05
    with pytest.raises(VicDrakeError, match="cannot tell.*--controller cs"):
        identify_controller(real)


@pytest.mark.realdata
def test_constant_stiffness_at_k_min_gives_no_r(logs):
    """K_z logged at its lower bound throughout: R cannot be read off it."""
    real = logs["test_tracking5"].copy()
    real["stiffness_z_N_per_m"] = real["stiffness_z_min_N_per_m"]
    with pytest.raises(VicDrakeError, match="cannot read R.*--R"):
        identify_controller(real)
    assert identify_controller(real, r_weight=0.1).controller == "vs-cf"


def test_other_layouts_and_controllers_are_refused():
    import pandas as pd

    palpation = pd.DataFrame({"t_s": [0.0, 0.1]})
    palpation.attrs["layout"] = "palpation"
    with pytest.raises(VicDrakeError, match="'palpation'"):
        identify_controller(palpation)
    scan = pd.DataFrame({"t_s": [0.0, 0.1]})
    scan.attrs["layout"] = "scan"
    with pytest.raises(VicDrakeError, match="cs or cf"):
        identify_controller(scan, controller="vs-vf")
    with pytest.raises(VicDrakeError, match="must be one of cs, cf, vs-cf, vs-vf"):
        identify_controller(scan, controller="pid")
