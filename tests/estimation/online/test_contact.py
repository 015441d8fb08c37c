"""The contact gate: a contact ends where its force falls back to the
free-air level it rose from, even above the contact threshold (a sensor
biased on the pressing side, a tissue that draws away from the probe);
that level, confirmed in free air, tares the force."""

import math

import numpy as np
import pytest

from tests.estimation.online.hc_data import hc_palpation
from vic_drake.estimation.online import OnlineEstimatorParams, run_online
from vic_drake.estimation.online.contact import (
    FALLEN,
    ONSET,
    RISEN,
    TARE,
    advance_gate,
    gate_initial_state,
)

KAPPA, LAM, BETA = 4000.0, 30000.0, 1.35
DT = 0.002


def _chest_draws_away(bias_N, *, seed=0, noise_N=0.05):
    """The tip comes down at 15 mm/s from 5 mm above a surface at 0.1 m and
    stops 6 mm deep (at 0.5 s); over 1.5-2.0 s the surface sinks 10 mm (it
    leaves the tip), over 3.0-3.5 s it comes back. The sensor reads a bias
    on the pressing side throughout.

    Returns:
        (t, z, z_dot, force, surface, tissue force).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 5.0, DT)
    ramp = np.clip((t - 1.5) / 0.5, 0.0, 1.0) - np.clip((t - 3.0) / 0.5, 0.0, 1.0)
    s = 0.1 - 0.010 * ramp
    s_dot = np.gradient(s, DT)
    z = np.maximum(0.105 - 0.015 * t, 0.094)
    z_dot = np.where(z > 0.094, -0.015, 0.0)
    eps = np.maximum(s - z, 0.0)
    tissue = np.maximum((KAPPA + LAM * (s_dot - z_dot)) * eps**BETA, 0.0)
    force = tissue + bias_N + rng.normal(0.0, noise_N, t.size)
    return t, z, z_dot, force, s, tissue


def _gate_phases(t, z, force, params, *, tares=False):
    """The gate's phase after each sample (and its tare, ``tares``)."""
    g = gate_initial_state()
    phases, tare = np.empty(t.size), np.empty(t.size)
    previous = math.nan
    for k in range(t.size):
        dt = 0.0 if math.isnan(previous) else t[k] - previous
        previous = t[k]
        phases[k] = advance_gate(g, 0, dt, z[k], force[k], params)
        tare[k] = g[TARE]
    return (phases, tare) if tares else phases


@pytest.mark.parametrize("bias_N", [0.8, 1.6, 2.5])
def test_the_gate_falls_when_the_tissue_leaves_a_biased_probe(bias_N):
    params = OnlineEstimatorParams()
    t, z, _, force, _, tissue = _chest_draws_away(bias_N)
    phases = _gate_phases(t, z, force, params)
    assert phases[0] == ONSET  # the bias arms the gate in free air
    gone = np.flatnonzero(tissue == 0.0)
    left = gone[np.searchsorted(t[gone], 1.5)]  # the tissue leaves the tip
    fell = np.flatnonzero(phases == FALLEN)
    assert fell.size and t[left] <= t[fell[0]] <= t[left] + 0.1
    back = np.flatnonzero((t > 3.0) & (tissue > 0.0))[0]
    risen = np.flatnonzero((phases == RISEN) & (t > t[fell[0]]))
    assert risen.size and t[back] <= t[risen[0]] <= t[back] + 0.3
    assert np.all(phases[(t > t[fell[0]]) & (t < t[back])] == FALLEN)


@pytest.mark.parametrize("method", ["rls", "ekf"])
def test_a_biased_probe_the_tissue_has_left_is_out_of_contact(method):
    """The surface latched at contact: once the tissue has left, the bias
    at the latched depth would read as a much softer tissue. The estimate
    is held instead, and the contact comes back with the tissue."""
    t, z, v, force, _, tissue = _chest_draws_away(1.6)
    params = OnlineEstimatorParams(method=method, kappa_prior=3000.0)
    trace = run_online(t, z, v, force, math.nan, params)
    away = (t > 1.9) & (t < 3.0)
    assert np.all(tissue[away] == 0.0)
    assert not trace.in_contact[away].any()
    assert np.all(trace.kappa[away] == trace.kappa[np.flatnonzero(away)[0]])
    assert trace.in_contact[t > 4.0].all()
    # Without the fall, the bias stands in for the tissue.
    params.contact_fall_air_travel_m = 1.0
    trace = run_online(t, z, v, force, math.nan, params)
    assert trace.in_contact[away].mean() > 0.9


def test_the_slope_fit_restarts_when_the_force_falls_back():
    """The map-free controller's estimator (EKF on the slope fit's surface):
    out of contact while the tissue is away, its estimate held."""
    t, z, v, force, _, _ = _chest_draws_away(1.6)
    params = OnlineEstimatorParams(method="ekf", surface_from_slope=True)
    trace = run_online(t, z, v, force, math.nan, params)
    away = (t > 1.9) & (t < 3.0)
    assert not trace.in_contact[away].any()
    assert np.all(trace.kappa[away] == trace.kappa[np.flatnonzero(away)[0]])
    params.contact_fall_air_travel_m = 1.0
    trace = run_online(t, z, v, force, math.nan, params)
    assert trace.in_contact[away].mean() > 0.9


def test_an_unbiased_contact_ends_at_the_threshold():
    """With no bias the level is below the threshold: the gate does not
    fall, and the contact ends where the force crosses the threshold."""
    t, z, v, force, _, _ = _chest_draws_away(0.0)
    params = OnlineEstimatorParams(kappa_prior=3000.0)
    assert not np.any(_gate_phases(t, z, force, params) == FALLEN)
    trace = run_online(t, z, v, force, math.nan, params)
    ended = np.flatnonzero((t > 1.5) & ~trace.in_contact.astype(bool))[0]
    below = np.flatnonzero((t > 1.5) & (force <= params.contact_threshold_N))[0]
    assert ended == below


@pytest.mark.parametrize("bias_N", [0.0, 1.0])
def test_a_palpation_that_starts_pressed_in_never_falls(bias_N):
    """The data start in contact: the level is tissue force, and a cycle
    that comes back to the starting depth has not left the tissue."""
    t, z, _, force, _ = hc_palpation(2000.0, 20000.0, seed=1)
    phases = _gate_phases(t, z, force + bias_N, OnlineEstimatorParams())
    assert not np.any(phases == FALLEN)
    assert np.any(phases == RISEN)


def test_a_dither_in_contact_is_no_free_air_descent():
    """A press that starts in contact with a 0.3 mm dither: the back and
    forth at the level does not add up to free air."""
    t = np.arange(0.0, 6.0, DT)
    eps = 0.002 + 3e-4 * np.sin(2.0 * np.pi * 3.0 * t)
    force = 3000.0 * eps**BETA + 1.0
    g = gate_initial_state()
    for k in range(t.size):
        advance_gate(
            g, 0, DT if k else 0.0, 0.1 - eps[k], force[k], OnlineEstimatorParams()
        )
    assert g[3] < 1e-3


def test_a_spike_in_free_air_does_not_rise():
    """Free air with a bias: a -50 N spike, then a +50 N spike; no rise,
    so no contact to fall from."""
    params = OnlineEstimatorParams()
    t = np.arange(0.0, 1.0, DT)
    force = np.full(t.size, 1.5)
    force[100], force[300] = -48.5, 51.5
    z = 0.11 - 0.015 * t
    phases = _gate_phases(t, z, force, params)
    assert np.all(phases == ONSET)


def test_without_the_filter_the_gate_never_falls():
    params = OnlineEstimatorParams(latch_rise_filter_s=0.0)
    t, z, _, force, _, _ = _chest_draws_away(1.6)
    phases = _gate_phases(t, z, force, params)
    assert not np.any(phases == FALLEN)


@pytest.mark.parametrize("bias_N", [0.8, 1.6, 2.5])
def test_the_tare_is_the_bias_once_the_tip_has_descended_in_free_air(bias_N):
    """The tip comes down 5 mm in free air before it touches (at 0.33 s):
    0 until the filter has settled (0.15 s) and the tip has gone down 2 mm
    more (0.28 s), then the bias to within the filtered noise, through the
    contact and after the tissue comes back. At the fall (the tissue
    leaves), the tare is the filtered force, still coming down to the
    level: it follows it within 0.1 s."""
    t, z, _, force, _, _ = _chest_draws_away(bias_N)
    phases, tare = _gate_phases(t, z, force, OnlineEstimatorParams(), tares=True)
    assert np.all(tare[t < 0.28] == 0.0)
    fell = t[np.flatnonzero(phases == FALLEN)[0]]
    settled = (t > 0.29) & ((t < fell) | (t > fell + 0.1))
    assert np.all(np.abs(tare[settled] - bias_N) < 0.05)
    assert np.all(np.abs(tare[t > fell] - bias_N) < 0.25)


@pytest.mark.parametrize("first_sample_offset_N", [-0.45, -0.2, 0.45])
def test_a_noisy_first_sample_does_not_set_the_level(first_sample_offset_N):
    """A sensor noisier than the fall margin (0.34 N std, as in a campaign
    run) whose first sample is off its bias: the level, and so the tare,
    is the settled filter's, not that sample's."""
    t, z, _, force, _, _ = _chest_draws_away(2.1, noise_N=0.34)
    force[0] = 2.1 + first_sample_offset_N
    phases, tare = _gate_phases(t, z, force, OnlineEstimatorParams(), tares=True)
    assert np.all(phases[t < 0.33] == ONSET)  # no rise in free air
    assert np.all(np.abs(tare[(t > 0.29) & (t < 1.5)] - 2.1) < 0.15)


@pytest.mark.parametrize(
    "method, from_slope", [("rls", False), ("ekf", False), ("ekf", True)]
)
@pytest.mark.parametrize("first_sample_offset_N", [-0.6, -0.45])
def test_a_noisy_first_sample_does_not_confirm_a_latch_in_free_air(
    method, from_slope, first_sample_offset_N
):
    """The surface latch's own low-pass, started from a first sample below a
    2.1 N bias, once "rose" from it as it settled and confirmed a latch in
    free air, before the tare: the estimator then updated on free-air
    samples. No sample with the tip above the surface is in contact."""
    params = OnlineEstimatorParams(
        method=method, kappa_prior=3000.0, surface_from_slope=from_slope
    )
    for seed in range(5):
        t, z, v, force, _, _ = _chest_draws_away(2.1, noise_N=0.34, seed=seed)
        force[0] = 2.1 + first_sample_offset_N
        trace = run_online(t, z, v, force, math.nan, params)
        in_free_air = z > 0.1005  # the tip 0.5 mm or more above the surface
        assert not np.any(trace.column("in_contact")[in_free_air] > 0), seed


@pytest.mark.parametrize("bias_N", [-1.0, 0.0, 0.4])
def test_no_tare_at_or_below_the_threshold(bias_N):
    t, z, _, force, _, _ = _chest_draws_away(bias_N)
    _, tare = _gate_phases(t, z, force, OnlineEstimatorParams(), tares=True)
    assert np.all(tare == 0.0)


def test_no_tare_on_a_tissue_soft_enough_to_be_flat_at_the_threshold():
    """kappa 300: the force stays within the fall margin over more than the
    free-air travel after it crosses the threshold, but the level is the
    threshold's, not a reading above it."""
    t = np.arange(0.0, 2.0, DT)
    z = 0.105 - 0.015 * t
    force = 300.0 * np.maximum(0.1 - z, 0.0) ** BETA
    params = OnlineEstimatorParams()
    flat = (force > 0.5) & (force < 0.7)
    assert np.ptp(z[flat]) > params.contact_fall_air_travel_m
    _, tare = _gate_phases(t, z, force, params, tares=True)
    assert np.all(tare == 0.0)


def test_the_tare_ends_when_the_reading_drops_to_the_threshold():
    """A bias of 1.6 N that goes away in free air (at 0.3 s)."""
    t = np.arange(0.0, 0.6, DT)
    z = 0.11 - 0.015 * t
    force = np.where(t < 0.3, 1.6, 0.0)
    _, tare = _gate_phases(t, z, force, OnlineEstimatorParams(), tares=True)
    assert tare[np.flatnonzero(t < 0.3)[-1]] == pytest.approx(1.6)
    assert np.all(tare[t > 0.4] == 0.0)


@pytest.mark.parametrize(
    "method, from_slope", [("rls", False), ("ekf", False), ("ekf", True)]
)
def test_a_biased_probe_estimates_as_an_unbiased_one(method, from_slope):
    """Before the tissue leaves (1.4 s), the tared estimate and its surface
    are those of the same data without the bias; untared (the free-air
    travel never reached), the bias moves the surface by a millimetre or
    more and kappa by percents."""
    params = OnlineEstimatorParams(
        method=method, kappa_prior=3000.0, surface_from_slope=from_slope
    )
    k = int(round(1.4 / DT))

    def at_1_4_s(bias_N, params):
        t, z, v, force, _, _ = _chest_draws_away(bias_N)
        trace = run_online(t, z, v, force, math.nan, params)
        return trace.kappa[k], trace.column("surface_z_m")[k]

    kappa0, surface0 = at_1_4_s(0.0, params)
    kappa, surface = at_1_4_s(1.6, params)
    assert kappa == pytest.approx(kappa0, rel=0.01)
    assert surface == pytest.approx(surface0, abs=5e-5)
    params.contact_fall_air_travel_m = 1.0
    kappa, surface = at_1_4_s(1.6, params)
    assert abs(kappa / kappa0 - 1.0) > 0.02
    assert abs(surface - surface0) > 1e-3
