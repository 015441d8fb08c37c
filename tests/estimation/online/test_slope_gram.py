"""The slope fit's normal equations in pure floats against numpy's direct
weighted least squares, and the fit's handling of faulty samples."""

import math

import numpy as np
import pytest

from vic_drake.estimation.online import OnlineEstimatorParams, run_online
from vic_drake.estimation.online.slope import (
    SLOPE_SIZE,
    slope_initial_state,
    slope_step,
)
from vic_drake.estimation.online.slope_gram import (
    SUMS_SIZE,
    add_sample,
    shift_basis,
    solve_sums,
)

MEMORY_S = 0.2


def random_samples(rng, n=150):
    """tau (s, up to 0), e = z0 - z (m), v = -z_dot (m/s), force (N): a
    cubic trend, a slope of 2000 N/m and a damping of 30 N s/m, with noise."""
    tau = np.sort(rng.uniform(-0.6, 0.0, n))
    e = rng.normal(0.0, 3e-4, n) + 2e-3 * tau
    v = rng.normal(0.0, 5e-3, n)
    trend = 5.0 + 2.0 * tau - 3.0 * tau**2 + 4.0 * tau**3
    force = trend + 2000.0 * e + 30.0 * v + rng.normal(0.0, 0.05, n)
    return tau, e, v, force


def design(tau, e, v):
    return np.column_stack([np.ones_like(tau), tau, tau**2, tau**3, e, v])


def sums_of(tau, e, v, force, w):
    sums = [0.0] * SUMS_SIZE
    for row in zip(w.tolist(), tau.tolist(), e.tolist(), v.tolist(), force.tolist()):
        sums = add_sample(sums, *row)
    return sums


def unpack(sums):
    G = np.zeros((6, 6))
    G[np.triu_indices(6)] = sums[:21]
    G = G + np.triu(G, 1).T
    return G, np.array(sums[21:27]), sums[27]


@pytest.mark.parametrize("seed", range(5))
def test_sums_and_solve_match_a_direct_weighted_least_squares(seed):
    rng = np.random.default_rng(seed)
    tau, e, v, force = random_samples(rng)
    w = np.exp(tau / MEMORY_S)
    X = design(tau, e, v)
    G, b, ff = unpack(sums_of(tau, e, v, force, w))
    np.testing.assert_allclose(G, X.T @ (w[:, None] * X), rtol=1e-12, atol=0.0)
    np.testing.assert_allclose(b, X.T @ (w * force), rtol=1e-12)
    assert ff == pytest.approx(np.sum(w * force**2), rel=1e-12)

    schur_z, coef_z, residual, g_inv_zz = solve_sums(sums_of(tau, e, v, force, w))
    sw = np.sqrt(w)
    coef = np.linalg.lstsq(sw[:, None] * X, sw * force, rcond=None)[0]
    trend = np.linalg.lstsq(sw[:, None] * X[:, :4], sw * e, rcond=None)[0]
    assert coef_z == pytest.approx(coef[4], rel=1e-9)
    assert coef_z == pytest.approx(2000.0, rel=0.05)  # the data's own slope
    assert residual == pytest.approx(np.sum(w * (force - X @ coef) ** 2), rel=1e-9)
    assert schur_z == pytest.approx(np.sum(w * (e - X[:, :4] @ trend) ** 2), rel=1e-9)
    assert g_inv_zz == pytest.approx(
        np.linalg.inv(X.T @ (w[:, None] * X))[4, 4], rel=1e-9
    )


@pytest.mark.parametrize("seed", range(5))
def test_shift_basis_is_the_sums_built_in_the_shifted_basis(seed):
    rng = np.random.default_rng(100 + seed)
    tau, e, v, force = random_samples(rng)
    w = np.exp(tau / MEMORY_S)
    d, dz = rng.uniform(0.002, 0.05), rng.normal(0.0, 1e-3)
    scale = math.exp(-d / MEMORY_S)
    shifted = shift_basis(sums_of(tau, e, v, force, w), d, dz, scale)
    direct = sums_of(tau - d, e + dz, v, force, w * scale)
    G, b, ff = unpack(shifted)
    G_ref, b_ref, ff_ref = unpack(direct)
    # Each entry to 1e-12 of the bound Cauchy-Schwarz puts on it.
    diag = np.sqrt(np.diag(G_ref))
    assert np.all(np.abs(G - G_ref) <= 1e-12 * np.outer(diag, diag))
    assert np.all(np.abs(b - b_ref) <= 1e-12 * diag * math.sqrt(ff_ref))
    assert ff == pytest.approx(ff_ref, rel=1e-14)


def test_solve_refuses_a_gram_that_is_not_positive_definite():
    rng = np.random.default_rng(7)
    tau, e, v, force = random_samples(rng)
    w = np.exp(tau / MEMORY_S)
    assert solve_sums(sums_of(tau, e, v, force, w)) is not None
    # A still tip (z = z0: a zero z column), no z_dot, a NaN among the sums.
    assert solve_sums(sums_of(tau, 0.0 * e, v, force, w)) is None
    assert solve_sums(sums_of(tau, e, 0.0 * v, force, w)) is None
    sums = sums_of(tau, e, v, force, w)
    sums[6] = math.nan
    assert solve_sums(sums) is None


def test_slope_step_reports_the_direct_fit_of_its_samples():
    """Every 10th sample, slope_step's k, its relative standard error and the
    motion beyond the trend are those of numpy's weighted least squares over
    all samples so far (weights exp(-age / memory))."""
    rng = np.random.default_rng(3)
    n = 400  # 0.8 s at 500 Hz: 40 solves
    t = np.arange(n) * 0.002
    e = rng.normal(0.0, 3e-4, n)
    v = rng.normal(0.0, 5e-3, n)
    z = 0.1 - e
    force = 5.0 + 3.0 * t + 2000.0 * e + 30.0 * v + rng.normal(0.0, 0.05, n)
    params = OnlineEstimatorParams(method="ekf", surface_from_slope=True)
    state = slope_initial_state()
    checked = 0
    for k in range(n):
        state, est = slope_step(state, t[k], z[k], -v[k], force[k], params)
        if (k + 1) % 10:
            continue
        w = np.exp((t[: k + 1] - t[k]) / MEMORY_S)
        X = design(t[: k + 1] - t[k], e[: k + 1], v[: k + 1])
        sw = np.sqrt(w)
        coef = np.linalg.lstsq(sw[:, None] * X, sw * force[: k + 1], rcond=None)[0]
        trend = np.linalg.lstsq(sw[:, None] * X[:, :4], sw * e[: k + 1], rcond=None)[0]
        residual2 = np.sum(w * (force[: k + 1] - X @ coef) ** 2) / w.sum()
        g_inv = np.linalg.inv(X.T @ (w[:, None] * X))
        rel_std = math.sqrt(residual2 * g_inv[4, 4] * 0.5) / abs(coef[4])
        motion = math.sqrt(np.sum(w * (e[: k + 1] - X[:, :4] @ trend) ** 2) / w.sum())
        assert est.slope_N_per_m == pytest.approx(coef[4], rel=1e-9)
        assert est.slope_rel_std == pytest.approx(rel_std, rel=1e-8)
        assert est.motion_m == pytest.approx(motion, rel=1e-9)
        if est.valid:
            mean_force = np.sum(w * force[: k + 1]) / w.sum()
            eps = params.beta * mean_force / coef[4]
            assert est.penetration_m == pytest.approx(eps, rel=1e-9)
            checked += 1
    assert checked > 10  # valid solves after 2 memories


def test_faulty_samples_leave_the_fit_and_the_ekf_finite():
    """NaN and inf samples, +-50 N spikes, a 1 s dropout and a contact loss
    in a dithered press: no NaN in kappa, the surface or the fit's sums, and
    kappa back within 5 % of the truth by the end."""
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 12.0, 0.002)
    w = 2.0 * np.pi * 3.0
    surface = 0.1 + 0.001 * t
    eps = 0.006 + 3e-4 * np.sin(w * t)
    eps_dot = 3e-4 * w * np.cos(w * t)
    force = (6000.0 + 40000.0 * eps_dot) * eps**1.35 + rng.normal(0.0, 0.045, t.size)
    z, z_dot = surface - eps, 0.001 - eps_dot
    spikes = rng.choice(t.size, 40, replace=False)
    force[spikes] += rng.choice([-50.0, 50.0], spikes.size)
    for k in rng.choice(t.size, 30, replace=False):
        (z, z_dot, force)[k % 3][k] = (math.nan, math.inf, -math.inf)[k % 3]
    lift = (t > 5.0) & (t < 5.3)  # contact lost
    force[lift], z[lift] = 0.0, z[lift] + 0.01
    keep = ~((t > 7.0) & (t < 8.0))  # a dropout: no samples for 1 s
    params = OnlineEstimatorParams(
        method="ekf", surface_from_slope=True, surface_walk_m_per_sqrt_s=0.0
    )
    args = (t[keep], z[keep], z_dot[keep], force[keep])
    trace = run_online(*args, math.nan, params)
    assert np.all(np.isfinite(trace.kappa)) and np.all(np.isfinite(trace.lam))
    contact = trace.in_contact
    assert contact.sum() > 0.8 * keep.sum()
    assert np.all(np.isfinite(trace.column("surface_z_m")[contact]))
    fit = trace.final_state[-SLOPE_SIZE:]  # the fit's state follows the EKF's
    assert np.all(np.isfinite(fit[5 : 5 + SUMS_SIZE]))  # its sums
    assert abs(trace.kappa[-1] / 6000.0 - 1.0) < 0.05
