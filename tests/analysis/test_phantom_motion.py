"""The phantom's motion estimated from a scan: known lifts, nominal scans, real logs."""

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from tests.analysis.scans import make_scan
from vic_drake.analysis.contact import contact_loss_intervals
from vic_drake.analysis.phantom_motion import (
    SIGNIFICANCE_Z,
    SIGNIFICANT_FRACTION,
    estimate_phantom_motion,
    lift_table,
    longest_excursion_s,
    map_surface_error_m,
    motion_is_significant,
    motion_significance,
    penetration_m,
    replay_table,
    unexplained_loss_z,
)
from vic_drake.errors import VicDrakeError
from vic_drake.tissue import hunt_crossley_force
from vic_drake.tissue.phantom import GridPhantom

KAPPA, LAM, BETA, SURFACE = 4000.0, 40000.0, 1.35, 0.1


def _flat_phantom() -> GridPhantom:
    xs, ys = np.linspace(-0.2, 0.1, 31), np.linspace(-0.45, -0.28, 18)
    full = np.ones((31, 18))
    return GridPhantom(
        x_m=xs,
        y_m=ys,
        z_m=SURFACE * full,
        kappa=KAPPA * full,
        lam=LAM * full,
        beta=BETA,
    )


def _scan_over(lift, z, t, noise_N=0.0, seed=0):
    """A scan whose force is the Hunt-Crossley law (with its viscous term)."""
    eps = SURFACE + lift - z
    f = hunt_crossley_force(
        eps, np.gradient(eps, t), KAPPA, LAM, BETA, clip_tension=True
    )
    f = f + np.random.default_rng(seed).normal(0.0, noise_N, t.size)
    return make_scan(t, f, x_m=0.03 - 0.01 * t, y_m=-0.36, z_m=z)


def _ramp(t, t0, t1):
    return np.clip((t - t0) / (t1 - t0), 0.0, 1.0)


def test_recovers_a_lift_and_a_drop_below_the_tip_within_its_band():
    """A rise of 12 mm, then a drop of 8 mm faster than the tip follows: the
    probe loses contact, and there the bound from the tip limits the estimate."""
    t = np.arange(0.0, 12.0, 0.002)
    lift = 0.012 * (_ramp(t, 2, 3) - _ramp(t, 4, 5))
    lift -= 0.008 * (_ramp(t, 6.0, 6.3) - _ramp(t, 8.0, 8.6))
    # The tip rides the surface (pushed up by half the lift) but sinks
    # slowly: it lags a fast drop by up to 4 mm, so the contact is lost.
    z = 0.093 + 0.5 * np.clip(lift, 0.0, None)
    z -= 0.008 * (_ramp(t, 6.0, 7.4) - _ramp(t, 8.0, 8.6)) * 0.5
    z += 0.004 * (_ramp(t, 6.0, 6.3) - _ramp(t, 6.3, 7.4))
    df = _scan_over(lift, z, t, noise_N=0.045)
    losses = contact_loss_intervals(df)
    assert len(losses) == 1 and losses[0][1] - losses[0][0] > 0.3
    est = estimate_phantom_motion(df, _flat_phantom(), map_surface_sigma_m=2e-4)
    err = est["phantom_lift_m"].to_numpy() - lift
    sigma = est["phantom_lift_sigma_m"].to_numpy()
    assert np.mean(np.abs(err) <= sigma) > 0.9
    assert np.all(np.abs(err) <= 3 * sigma)
    gap = ~est["measured"].to_numpy()
    in_loss = (t > losses[0][0]) & (t < losses[0][1])
    assert np.all(gap[in_loss])
    # The bound holds the truth, and it is what limits the estimate: the
    # linear bridge between the loss's ends lies above the tip.
    upper = est["upper_bound_m"].to_numpy()
    assert np.all(lift[in_loss] <= upper[in_loss] + 1e-6)
    m = est["measured"].to_numpy()
    bridge = np.interp(t, t[m], est["phantom_lift_m"].to_numpy()[m])
    assert np.max(bridge[in_loss] - upper[in_loss]) > 5e-4
    assert np.all(est["phantom_lift_m"].to_numpy()[in_loss] <= upper[in_loss])
    assert motion_is_significant(est)
    assert replay_table(est) == lift_table(est)
    table = lift_table(est, dt_s=0.1)
    assert len(table) == 120 and table[35][1] == pytest.approx(0.012, abs=5e-4)


def test_nominal_scan_has_no_motion_and_is_not_replayed():
    t = np.arange(0.0, 10.0, 0.002)
    z = 0.093 + 0.002 * np.sin(2 * np.pi * 0.3 * t)  # The tip rides up and down.
    df = _scan_over(np.zeros_like(t), z, t, noise_N=0.045)
    est = estimate_phantom_motion(df, _flat_phantom())
    motion = est["phantom_lift_m"].to_numpy()
    assert np.all(np.abs(motion) <= est["phantom_lift_sigma_m"].to_numpy())
    assert np.max(np.abs(motion)) < 2e-4
    assert motion_significance(est) == 0.0 and not motion_is_significant(est)
    assert replay_table(est) == []


def _chase(t, drop_m, drop_s, t0=6.0, tip_rate=0.02):
    """A drop of the surface faster than the tip that chases it at tip_rate."""
    lift = -drop_m * _ramp(t, t0, t0 + drop_s)
    z = 0.093 - drop_m * _ramp(t, t0, t0 + drop_m / tip_rate)
    return lift, z


def test_a_contact_loss_the_resting_phantom_cannot_explain_is_significant():
    """A 15 mm drop in 0.1 s: the probe loses contact for 0.45 s (the viscous
    term cuts the force at once) and sinks 9 mm meanwhile without touching. With a map error of 6 mm (3 sigma above
    the drop) no sample leaves the band, so only the loss says the phantom
    moved; the old rule (the fraction alone) did not replay it."""
    t = np.arange(0.0, 10.0, 0.002)
    lift, z = _chase(t, 0.015, 0.1)
    df = _scan_over(lift, z, t, noise_N=0.045)
    losses = contact_loss_intervals(df)
    assert len(losses) == 1 and 0.4 < losses[0][1] - losses[0][0] < 0.5
    est = estimate_phantom_motion(df, _flat_phantom(), map_surface_sigma_m=6e-3)
    assert motion_significance(est) == 0.0 and longest_excursion_s(est) == 0.0
    assert unexplained_loss_z(est) > 2 * SIGNIFICANCE_Z
    assert motion_is_significant(est)
    assert replay_table(est) == lift_table(est)


def test_a_contact_loss_the_tip_makes_itself_is_not_evidence():
    """The tip lifts off a resting phantom for 0.5 s mid-scan and comes back,
    and bounces at the first touch: the losses need no motion."""
    t = np.arange(0.0, 10.0, 0.002)
    z = 0.093 + 0.012 * (_ramp(t, 5.0, 5.2) - _ramp(t, 5.7, 5.9))
    z += 0.009 * (_ramp(t, 0.3, 0.32) - _ramp(t, 0.36, 0.4))
    df = _scan_over(np.zeros_like(t), z, t, noise_N=0.045)
    assert len(contact_loss_intervals(df)) == 2
    est = estimate_phantom_motion(df, _flat_phantom())
    assert unexplained_loss_z(est) < 1.0
    assert not motion_is_significant(est)


def test_a_short_scan_with_one_excursion_is_significant():
    """A 9 mm lift held 0.6 s in a 20 s scan: 5 % of the samples lie beyond
    3 sigma (under the old rule's 10 %), in one run of three averaging windows."""
    t = np.arange(0.0, 20.0, 0.002)
    lift = 0.009 * (_ramp(t, 8.0, 8.3) - _ramp(t, 9.0, 9.3))
    z = 0.093 + 0.8 * lift
    df = _scan_over(lift, z, t, noise_N=0.045)
    est = estimate_phantom_motion(df, _flat_phantom(), map_surface_sigma_m=2e-3)
    assert 0.02 < motion_significance(est) < SIGNIFICANT_FRACTION
    assert longest_excursion_s(est) > 0.5
    assert motion_is_significant(est)


@pytest.mark.parametrize("fault", ["spike", "dropout", "noisy stretch", "z glitch"])
def test_one_odd_sample_or_one_noisy_stretch_is_not_motion(fault):
    """A resting phantom whose log has one force spike of 25 N, one sample of
    no force, 0.3 s of 3 N noise or one tip sample 20 mm off: nothing is replayed."""
    t = np.arange(0.0, 12.0, 0.002)
    df = _scan_over(np.zeros_like(t), np.full_like(t, 0.093), t, noise_N=0.045)
    f = -df["force_sensor_z_N"].to_numpy().copy()
    i = 3000
    if fault == "spike":
        f[i] += 25.0
    elif fault == "dropout":
        f[i] = 0.0
    elif fault == "noisy stretch":
        f[i : i + 150] += np.random.default_rng(1).normal(0.0, 3.0, 150)
    else:
        z = df["z_m"].to_numpy().copy()
        z[i] -= 0.02
        df["z_m"] = z
    df["force_sensor_z_N"] = -f
    est = estimate_phantom_motion(df, _flat_phantom(), map_surface_sigma_m=1e-3)
    assert longest_excursion_s(est) < 0.4
    assert unexplained_loss_z(est) < SIGNIFICANCE_Z
    assert not motion_is_significant(est)


def test_viscous_inversion_beats_the_static_law_on_a_fast_indentation():
    t = np.arange(0.0, 4.0, 0.002)
    z = 0.095 - 0.004 * np.sin(2 * np.pi * 1.0 * t)  # 2.5 cm/s peak rate.
    df = _scan_over(np.zeros_like(t), z, t)
    eps_true = SURFACE - z
    static = penetration_m(df, _flat_phantom(), viscous=False)
    viscous = penetration_m(df, _flat_phantom(), viscous=True)
    inner = slice(100, -100)
    err_s = np.nanmax(np.abs(static - eps_true)[inner])
    err_v = np.nanmax(np.abs(viscous - eps_true)[inner])
    assert err_v < 0.5 * err_s


def test_a_nominal_reference_cancels_the_map_error():
    """The map's surface tilts 3.3 mm over the scan; a nominal log of the
    same scan cancels that."""
    t = np.arange(0.0, 10.0, 0.002)
    lift = 0.01 * (_ramp(t, 3, 4) - _ramp(t, 6, 7))
    z = 0.093 + 0.5 * lift
    df = _scan_over(lift, z, t)
    nominal = _scan_over(np.zeros_like(t), np.full_like(t, 0.093), t)
    wrong = _flat_phantom()
    wrong = GridPhantom(
        x_m=wrong.x_m,
        y_m=wrong.y_m,
        z_m=wrong.surface_m - 0.01 * (wrong.x_m[:, None] + 0.2) / 0.3,
        kappa=wrong.kappa_grid,
        lam=wrong.lam_grid,
        beta=BETA,
    )
    with_map = estimate_phantom_motion(df, wrong)
    with_nominal = estimate_phantom_motion(df, wrong, nominal=nominal)
    assert with_nominal.attrs["reference"] == "nominal log"
    err_map = np.abs(with_map["phantom_lift_m"] - lift).max()
    err_nom = np.abs(with_nominal["phantom_lift_m"] - lift).max()
    assert err_nom < 1e-3 < err_map and err_nom < err_map / 3
    assert np.median(with_nominal["phantom_lift_sigma_m"]) < np.median(
        with_map["phantom_lift_sigma_m"]
    )
    # The nominal log measures the map's error under the track; replayed with
    # the motion, it puts the simulated surface where the real one was.
    x = df["x_m"].to_numpy()
    map_error = map_surface_error_m(df, wrong, nominal)
    np.testing.assert_allclose(map_error, 0.01 * (x + 0.2) / 0.3, atol=1e-4)
    table = np.array(replay_table(with_nominal, surface_error_m=map_error))
    truth = np.interp(table[:, 0], t, lift + map_error)
    np.testing.assert_allclose(table[:, 1], truth, atol=1e-3)


def test_bad_input_is_named():
    t = np.arange(0.0, 2.0, 0.002)
    free = make_scan(t, np.zeros_like(t), x_m=0.0, y_m=-0.36, z_m=0.12)
    with pytest.raises(VicDrakeError, match="contact"):
        estimate_phantom_motion(free, _flat_phantom())
    with pytest.raises(VicDrakeError, match="z_m"):
        estimate_phantom_motion(pd.DataFrame({"t_s": t}), _flat_phantom())
    df = _scan_over(np.zeros_like(t), np.full_like(t, 0.093), t)
    with pytest.raises(VicDrakeError, match="smooth_s"):
        estimate_phantom_motion(df, _flat_phantom(), smooth_s=0.0)
    with pytest.raises(VicDrakeError, match="kappa_rel_sigma"):
        estimate_phantom_motion(df, _flat_phantom(), kappa_rel_sigma=-1.0)


@pytest.fixture(scope="module")
def simulated_scans():
    """A short CS scan of the synthetic chest with a scripted lift and drop,
    and the same scan without them (the estimator sees the exact map)."""
    from vic_drake.experiments.paper_scenarios import synthetic_scenario
    from vic_drake.experiments.scan_run import run_scan
    from vic_drake.scenario import DisturbanceConfig, PhantomLift

    base = synthetic_scenario("cs")
    trajectory = replace(
        base.trajectory, approach_z_m=0.085, initial_tip_z_m=0.0995, liftoff_height_m=0
    )
    # Lifted 15 mm, then dropped 25 mm in 0.2 s (faster than the probe
    # follows: contact is lost), held 10 mm under rest and raised again.
    lifts = [
        PhantomLift(start_s=1.5, height_m=0.015, rise_s=0.5, hold_s=1.0, fall_s=0.2),
        PhantomLift(start_s=3.2, height_m=-0.010, rise_s=0.2, hold_s=0.8, fall_s=0.5),
    ]
    disturbed = replace(
        base, trajectory=trajectory, disturbance=DisturbanceConfig(lifts=lifts)
    )
    nominal = replace(base, trajectory=trajectory)
    return run_scan(disturbed, duration_s=6.5).df, run_scan(nominal, duration_s=6.5).df


@pytest.mark.slow
def test_simulated_scan_lift_is_recovered_within_its_band(simulated_scans):
    from vic_drake.tissue.phantom import load_phantom

    df, _ = simulated_scans
    truth = df["phantom_lift_m"].to_numpy()
    est = estimate_phantom_motion(df, load_phantom("synthetic"))
    err = est["phantom_lift_m"].to_numpy() - truth
    sigma = est["phantom_lift_sigma_m"].to_numpy()
    measured = est["measured"].to_numpy()
    t = est["t_s"].to_numpy()
    after = t >= t[measured][0]
    assert np.mean(np.abs(err[after]) <= 2 * sigma[after]) > 0.95
    assert np.sqrt(np.mean(err[after & measured] ** 2)) < 1e-3
    losses = contact_loss_intervals(df)
    assert losses, "the drop should lose contact"
    motion = est["phantom_lift_m"].to_numpy()
    upper = est["upper_bound_m"].to_numpy()
    bridge = np.interp(t, t[measured], motion[measured])
    for t0, t1 in losses:
        inside = (t > t0) & (t < t1)
        assert np.all(np.abs(err[inside]) <= 2 * sigma[inside])
        assert np.all(motion[inside] <= upper[inside])
        # The bound is what limits the estimate: the bridge lies above the tip.
        assert np.max(bridge[inside] - upper[inside]) > 1e-3
    assert motion_is_significant(est)


@pytest.mark.slow
def test_out_of_contact_the_estimate_is_not_above_the_tip(simulated_scans):
    """Where contact is lost the surface has left the tip: the estimate lies at
    or under the tip's height (the loose bound above it only widens the band),
    and so the replay loses contact where the log did."""
    from vic_drake.tissue.phantom import load_phantom

    df, _ = simulated_scans
    phantom = load_phantom("synthetic")
    est = estimate_phantom_motion(df, phantom)
    t = est["t_s"].to_numpy()
    x, y = df["x_m"].to_numpy(), df["y_m"].to_numpy()
    # The map is the simulated tissue's own, so the baseline is ~0.
    tip = df["z_m"].to_numpy() - np.asarray(phantom.surface_z(x, y))
    motion = est["phantom_lift_m"].to_numpy()
    err = motion - df["phantom_lift_m"].to_numpy()
    losses = contact_loss_intervals(df)
    assert losses
    for t0, t1 in losses:
        inside = (t > t0) & (t < t1)
        assert np.max(motion[inside] - tip[inside]) < 0.1e-3
        assert np.mean(err[inside]) < 2e-3


@pytest.mark.slow
def test_simulated_nominal_scan_has_no_significant_motion(simulated_scans):
    from vic_drake.tissue.phantom import load_phantom

    _, df = simulated_scans
    est = estimate_phantom_motion(df, load_phantom("synthetic"))
    m = est["measured"].to_numpy()
    motion = est["phantom_lift_m"].to_numpy()[m]
    assert np.mean(np.abs(motion) <= est["phantom_lift_sigma_m"].to_numpy()[m]) > 0.95
    assert motion_significance(est) < SIGNIFICANT_FRACTION / 10
    assert longest_excursion_s(est) == 0.0 and unexplained_loss_z(est) == 0.0
    assert not motion_is_significant(est)


@pytest.mark.realdata
@pytest.mark.parametrize(
    "log", ["test_compliance_control400_dist", "test_force_control_dist"]
)
def test_real_contact_losses_lie_where_the_surface_is_below_the_tip(data_dir, log):
    """Each real loss lies where the estimate puts the surface under the tip,
    by a separation the penetration rates at its ends give; the sibling
    nominal log shows no motion of its own."""
    from vic_drake.analysis.columns import real_to_canonical
    from vic_drake.realdata import read_bag
    from vic_drake.tissue.phantom import load_phantom

    phantom = load_phantom("measured", data_dir=data_dir)
    bag = data_dir / "experiments" / log
    real = real_to_canonical(read_bag(bag))
    nominal = real_to_canonical(read_bag(bag.with_name(log[: -len("_dist")])))
    est = estimate_phantom_motion(real, phantom, nominal=nominal)
    assert motion_is_significant(est)
    t = est["t_s"].to_numpy()
    motion = est["phantom_lift_m"].to_numpy()
    upper = est["upper_bound_m"].to_numpy()
    losses = contact_loss_intervals(real)
    assert losses
    for t0, t1 in losses:
        inside = (t > t0) & (t < t1)
        assert not est["measured"].to_numpy()[inside].any()
        assert np.all(motion[inside] <= upper[inside])
        assert np.mean(upper[inside] - motion[inside]) > 1e-4
    quiet = estimate_phantom_motion(nominal, phantom)
    assert not motion_is_significant(quiet)


@pytest.mark.realdata
@pytest.mark.parametrize(
    "log",
    [
        "test_compliance_control400",
        "test_force_control",
        "test_tracking5",
        "test_nardi_matForce_lowR",
    ],
)
def test_the_nominal_logs_show_no_motion_by_any_test(data_dir, log):
    """No sample beyond 3 sigma, and the few dips under the contact threshold
    at the first touch (at most 12 ms) are no losses."""
    from vic_drake.analysis.columns import real_to_canonical
    from vic_drake.realdata import read_bag
    from vic_drake.tissue.phantom import load_phantom

    real = real_to_canonical(read_bag(data_dir / "experiments" / log))
    est = estimate_phantom_motion(real, load_phantom("measured", data_dir=data_dir))
    assert motion_significance(est) == 0.0
    assert longest_excursion_s(est) == 0.0
    assert unexplained_loss_z(est) == 0.0
    assert not motion_is_significant(est)
