"""Both online estimators (RLS, EKF) on simulated Hunt-Crossley data:
recovery of known parameters, faults (NaN, spikes, dropouts, contact loss)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.estimation.online.hc_data import hc_palpation
from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online import (
    OnlineEstimatorParams,
    ekf_initial_state,
    ekf_layout,
    rls_initial_state,
    rls_step,
    run_online,
)

METHODS = ("rls", "ekf")


@pytest.mark.parametrize("method", METHODS)
@settings(max_examples=6, deadline=None)
@given(
    kappa=st.floats(2000.0, 10000.0),
    lam_ratio=st.floats(3.0, 20.0),
    seed=st.integers(0, 1000),
)
def test_recovers_known_parameters_with_noise(method, kappa, lam_ratio, seed):
    lam = kappa * lam_ratio
    t, z, v, f, s = hc_palpation(kappa, lam, seed=seed, duration_s=6.0)
    trace = run_online(t, z, v, f, s, OnlineEstimatorParams(method=method))
    # Tolerances: 0.05 N noise on 3-10 N of force, 6 s of data.
    assert trace.kappa[-1] == pytest.approx(kappa, rel=0.02)
    assert trace.lam[-1] == pytest.approx(lam, rel=0.10)
    assert trace.valid[-1]
    assert np.all(np.isfinite(trace.values[:, :5]))


@pytest.mark.parametrize("method", METHODS)
def test_survives_nan_spikes_and_dropouts(method):
    kappa, lam = 5000.0, 40000.0
    t, z, v, f, s = hc_palpation(kappa, lam, seed=3)
    f = f.copy()
    z = z.copy()
    rng = np.random.default_rng(1)
    f[rng.choice(t.size, 60, replace=False)] = np.nan  # NaN samples
    z[rng.choice(t.size, 20, replace=False)] = np.inf
    spikes = rng.choice(t.size, 40, replace=False)
    f[spikes] += rng.choice([-50.0, 50.0], spikes.size)  # +-50 N spikes
    keep = np.ones(t.size, bool)
    keep[1000:1500] = False  # a 1 s dropout (no samples at all)
    trace = run_online(
        t[keep], z[keep], v[keep], f[keep], s, OnlineEstimatorParams(method=method)
    )
    assert np.all(np.isfinite(trace.values[:, :5]))
    assert trace.kappa[-1] == pytest.approx(kappa, rel=0.03)


@pytest.mark.parametrize("method", METHODS)
def test_holds_through_contact_loss_and_recontact(method):
    kappa, lam = 3000.0, 25000.0
    t, z, v, f, s = hc_palpation(kappa, lam, seed=4)
    lift = (t > 4.0) & (t < 5.0)
    z = np.where(lift, s + 0.01, z)
    f = np.where(lift, 0.0, f)
    trace = run_online(t, z, v, f, s, OnlineEstimatorParams(method=method))
    during = lift & (t > 4.1)
    assert not trace.in_contact[during].any() and not trace.valid[during].any()
    held = trace.kappa[during]
    assert np.ptp(held) == 0.0 and held[0] == pytest.approx(kappa, rel=0.03)
    assert trace.in_contact[-1] and trace.kappa[-1] == pytest.approx(kappa, rel=0.02)


@pytest.mark.parametrize("method", METHODS)
def test_unknown_surface_latched_at_first_contact(method):
    kappa, lam = 4000.0, 30000.0
    t, z, v, f, s = hc_palpation(kappa, lam, seed=5)
    params = OnlineEstimatorParams(method=method, kappa_prior=kappa, lam_prior=lam)
    trace = run_online(t, z, v, f, math.nan, params)
    first = np.flatnonzero(trace.in_contact)[0]
    # Latched where the prior gives the measured force: the true surface.
    assert trace.column("surface_z_m")[first] == pytest.approx(s, abs=2e-4)


def test_ekf_surface_state_corrects_a_surface_offset():
    kappa, lam = 4000.0, 30000.0
    t, z, v, f, s = hc_palpation(kappa, lam, seed=6, duration_s=10.0)
    params = OnlineEstimatorParams(method="ekf", surface_walk_m_per_sqrt_s=1e-4)
    trace = run_online(t, z, v, f, s - 0.002, params)  # map surface 2 mm low
    assert trace.column("surface_z_m")[-1] == pytest.approx(s, abs=5e-4)
    assert trace.kappa[-1] == pytest.approx(kappa, rel=0.15)


def test_ekf_layout_and_beta_state():
    p = OnlineEstimatorParams(
        method="ekf", estimate_beta=True, surface_walk_m_per_sqrt_s=1e-3
    )
    assert ekf_layout(p) == (4, 2, 3)
    assert len(ekf_initial_state(p)) == 9 + 4 + 16
    t, z, v, f, s = hc_palpation(4000.0, 30000.0, beta=1.35, seed=7)
    trace = run_online(t, z, v, f, s, p)
    assert np.all(np.isfinite(trace.values[:, :5]))


def test_step_is_pure():
    p = OnlineEstimatorParams()
    state = rls_initial_state(p)
    before = list(state)
    new, est = rls_step(state, 0.0, 0.095, 0.0, 5.0, 0.1, p)
    assert state == before and new != before
    assert est.in_contact == 1.0


@pytest.mark.parametrize(
    "field, value",
    [
        ("method", "ukf"),
        ("memory_s", 0.0),
        ("kappa_prior", -1.0),
        ("gate_sigma", math.nan),
        ("max_rel_change", 1.0),
    ],
)
def test_params_reject_bad_values(field, value):
    p = OnlineEstimatorParams()
    setattr(p, field, value)
    with pytest.raises(VicDrakeError, match=field):
        p.validate()


def test_estimate_beta_needs_ekf():
    with pytest.raises(VicDrakeError, match="estimate_beta"):
        OnlineEstimatorParams(method="rls", estimate_beta=True)
