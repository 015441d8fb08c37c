"""Scan summary and claims C4-C7 on small synthetic scans (each threshold on both sides)."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.analysis import claims as C
from vic_drake.errors import VicDrakeError


def _scan(force_pressing, *, t=None, z_d=0.085, ref=None, lift_at=None, **cols):
    n = len(force_pressing)
    t = np.arange(n) * 0.01 if t is None else t
    zd = np.full(n, z_d)
    if lift_at is not None:
        zd[t >= lift_at] = z_d + 0.05
    df = pd.DataFrame(
        {"t_s": t, "z_d_m": zd, "force_sensor_z_N": -np.asarray(force_pressing)}
    )
    if ref is not None:
        df["force_ref_z_N"] = -np.broadcast_to(ref, (n,))
    for k, v in cols.items():
        df[k] = np.broadcast_to(v, (n,))
    return df


def test_scan_metrics_rmse_range_and_lift_off():
    t = np.arange(0, 12, 0.01)
    f = 7 + 0.5 * np.sin(t)
    f[t >= 10.5] = 0.0  # lifted off
    m = C.scan_metrics(_scan(f, t=t, ref=7.0, lift_at=10.0))
    w = (t >= 1.0) & (t < 10.0)
    assert m["force_rmse_N"] == pytest.approx(
        np.sqrt(np.mean((f[w] - 7) ** 2)), rel=1e-9
    )
    assert m["force_range_N"] == pytest.approx(np.ptp(np.percentile(f[w], [2, 98])))
    assert m["lifted_off"] is True
    pressing = C.scan_metrics(_scan(7 + 0 * t, t=t, ref=7.0, lift_at=10.0))
    assert pressing["lifted_off"] is False and pressing[
        "force_rmse_N"
    ] == pytest.approx(0)
    no_ref = C.scan_metrics(_scan(f, t=t, ref=0.0, lift_at=10.0))
    assert "force_rmse_N" not in no_ref and no_ref["force_range_N"] > 0


def test_scan_metrics_needs_columns():
    with pytest.raises(VicDrakeError, match="force_sensor_z_N"):
        C.scan_metrics(pd.DataFrame({"t_s": np.arange(20.0), "z_d_m": 0.0}))


def test_c4_and_c5_thresholds():
    vscf = {"force_rmse_N": 0.6, "lifted_off": True, "force_range_N": 1.0}
    cf = {"force_rmse_N": 0.55, "lifted_off": False}
    cs = {"force_range_N": 2.5}
    assert C.claim_c4({"vs-cf": vscf, "cf": cf}, None).passed  # 0.6/0.55 = 1.09
    assert not C.claim_c4(
        {"vs-cf": {**vscf, "force_rmse_N": 0.7}, "cf": cf}, None
    ).passed
    assert not C.claim_c4(
        {"vs-cf": vscf, "cf": {**cf, "lifted_off": True}}, None
    ).passed
    assert not C.claim_c4(
        {"vs-cf": {**vscf, "lifted_off": False}, "cf": cf}, None
    ).passed
    # A CF run that never asked for a lift (the rig's logs end at the scan
    # height) does not test "CF cannot lift off": untested, not evidence.
    untested = {**cf, "lift_commanded": False}
    claim = C.claim_c4(None, {"vs-cf": vscf, "cf": untested})
    assert claim.pass_real and claim.real["cf_lifted_off"] is None
    still = C.claim_c4(None, {"vs-cf": {**vscf, "lifted_off": False}, "cf": untested})
    assert not still.pass_real  # VS-CF's lift was asked for and did not happen.
    assert C.claim_c5({"cs": cs, "vs-cf": vscf}, None).passed
    assert not C.claim_c5({"cs": {"force_range_N": 1.9}, "vs-cf": vscf}, None).passed
    assert not C.claim_c5({"cs": cs}, None).passed  # VS-CF missing: not evaluated


def test_c6_penetration_and_cap():
    t = np.arange(0, 10, 0.01)
    on = (t > 4) & (t < 6)
    ref = np.where(on, 12.0, 6.0)  # F_body(eps_d): above the 9 N cap on the rib
    f = np.where(on, 9.0, 6.0)
    pen = np.where(on, 0.004, 0.0075)
    df = _scan(f, t=t, ref=ref, force_min_z_N=-9.0, penetration_m=pen)
    m = C.scan_metrics(df, limits=C.ScanLimits(eps_d_m=0.008))
    assert m["penetration_error_off_ribs_median_m"] == pytest.approx(0.0005)
    assert m["force_on_ribs_p99_N"] == pytest.approx(9.0)
    assert C.claim_c6(m, None).passed
    over = C.scan_metrics(
        _scan(
            np.where(on, 11.0, 6.0), t=t, ref=ref, force_min_z_N=-9.0, penetration_m=pen
        )
    )
    assert not C.claim_c6(over, None).passed
    deep = C.scan_metrics(
        _scan(
            f,
            t=t,
            ref=ref,
            force_min_z_N=-9.0,
            penetration_m=np.where(on, 0.004, 0.012),
        )
    )
    assert not C.claim_c6(deep, None).passed


def test_c6_scan_off_the_ribs_is_not_evaluated_and_says_what_happened():
    """A VS-VF scan whose reference never reaches the cap cannot test the cap:
    not evaluated (never FAIL), with the scan's own numbers in the reason."""
    t = np.arange(0, 10, 0.01)
    df = _scan(
        np.full(t.size, 6.0),
        t=t,
        ref=np.full(t.size, 6.0),
        force_min_z_N=-9.0,
        penetration_m=np.full(t.size, 0.0079),
    )
    m = C.scan_metrics(df, limits=C.ScanLimits(eps_d_m=0.008))
    claim = C.claim_c6(m, None)
    assert claim.status == C.NOT_EVALUATED and not claim.passed
    assert claim.pass_sim is None and claim.sim["n_on_ribs"] == 0
    assert "exceeded the cap |F_min| on only 0 samples" in claim.detail
    assert "median |eps - eps_d| = 0.10 mm" in claim.detail
    assert "result missing" not in claim.detail
    # The penetration half alone can still fail the claim.
    deep = C.scan_metrics(
        _scan(
            np.full(t.size, 6.0),
            t=t,
            ref=np.full(t.size, 6.0),
            force_min_z_N=-9.0,
            penetration_m=np.full(t.size, 0.013),
        ),
        limits=C.ScanLimits(eps_d_m=0.008),
    )
    assert C.claim_c6(deep, None).status == C.FAIL


def test_claim_status_three_ways():
    cs, vscf = {"force_range_N": 4.0}, {"force_range_N": 1.0}
    assert C.claim_c5({"cs": cs, "vs-cf": vscf}, None).status == C.PASS
    assert C.claim_c5({"cs": {"force_range_N": 1.5}, "vs-cf": vscf}, None).status == (
        C.FAIL
    )
    missing = C.claim_c5({"cs": cs}, None)
    assert missing.status == C.NOT_EVALUATED and "no VS-CF scan" in missing.detail
    absent = C.claim_c5(None, None, reason_sim="the scans stage was not selected")
    d = absent.to_dict()
    assert d["status"] == "not evaluated" and d["pass"] is False
    assert "the scans stage was not selected" in d["detail"]
    # A real side that contradicts the claim is a fail even without a simulation.
    assert C.claim_c5(None, {"cs": {"force_range_N": 1.5}, "vs-cf": vscf}).status == (
        C.FAIL
    )


def _disturbed(peak=8.0, k_lost=100.0, power_min=-0.09, tank_min=0.45):
    t = np.arange(0, 10, 0.01)
    lost = (t > 4) & (t < 5)
    f = np.where(lost, 0.0, 7.0)
    f[np.argmin(np.abs(t - 5.2))] = peak
    k = np.where(lost, k_lost, 500.0)
    return C.scan_metrics(
        _scan(
            f,
            t=t,
            ref=7.0,
            stiffness_z_N_per_m=k,
            tank_energy_J=np.linspace(0.6, tank_min, t.size),
            tank_power_W=np.linspace(0, power_min, t.size),
        )
    )


def test_c7_passes_and_each_check_can_fail():
    others = {"cs": {"peak_force_N": 20.0}, "cf": {"peak_force_N": 14.0}}
    good = _disturbed()
    assert good["n_contact_losses"] == 1
    assert good["fraction_at_k_min_during_loss"] == pytest.approx(1.0)
    assert C.claim_c7({"vs-vf": good, **others}, None).passed
    for bad in (
        _disturbed(peak=15.0),
        _disturbed(k_lost=300.0),
        _disturbed(power_min=-0.2),
        _disturbed(tank_min=0.3),
    ):
        claim = C.claim_c7({"vs-vf": bad, **others}, None)
        assert not claim.passed, claim.sim["checks"]


def test_scan_limits_are_the_controllers_settings():
    import dataclasses

    from vic_drake.control.params import ControllerParams, real_controller_params

    p = ControllerParams()
    limits = C.ScanLimits()
    # The defaults are the default controller's; whether it aims at eps_d is
    # left open (None: a log of an unknown controller is scored on it).
    assert limits.targets_penetration is None
    assert dataclasses.replace(limits, targets_penetration=False) == (
        C.ScanLimits.from_controller(p)
    )
    assert limits.k_min_z_N_per_m == p.qp.stiffness_min_N_per_m[2]
    assert limits.power_max_W == -p.tank.power_limit_W
    aims = {
        c: C.ScanLimits.from_controller(real_controller_params(c)).targets_penetration
        for c in ("cs", "cf", "vs-cf", "vs-vf")
    }
    assert aims == {"cs": False, "cf": False, "vs-cf": False, "vs-vf": True}


def test_controllers_without_a_tank_have_nan_tank_metrics():
    """CS and CF have no tank: their log holds its initial energy (0.5 J,
    0 W), which is no tank minimum. VS keeps its figures; C7 reads only
    VS-VF's and passes as before."""
    from vic_drake.control.params import real_controller_params

    t = np.arange(0, 10, 0.01)
    flat = _scan(7 + 0 * t, t=t, ref=7.0, tank_energy_J=0.5, tank_power_W=0.0)
    for name in ("cs", "cf"):
        limits = C.ScanLimits.from_controller(real_controller_params(name))
        assert not limits.has_tank
        m = C.scan_metrics(flat, limits=limits)
        assert np.isnan(m["tank_min_J"]) and np.isnan(m["tank_power_min_W"])
    for name in ("vs-cf", "vs-vf"):
        limits = C.ScanLimits.from_controller(real_controller_params(name))
        assert limits.has_tank
        m = C.scan_metrics(flat, limits=limits)
        assert m["tank_min_J"] == 0.5 and m["tank_power_min_W"] == 0.0
    no_tank = C.ScanLimits.from_controller(real_controller_params("cs"))
    others = {
        k: C.scan_metrics(
            _scan(np.full(t.size, peak), t=t, tank_energy_J=0.5, tank_power_W=0.0),
            limits=no_tank,
        )
        for k, peak in (("cs", 20.0), ("cf", 14.0))
    }
    claim = C.claim_c7({"vs-vf": _disturbed(), **others}, None)
    assert claim.passed and claim.sim["tank_min_J"] == pytest.approx(0.45)
