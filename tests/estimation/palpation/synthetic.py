"""Synthetic palpation logs shared by the palpation and load-test tests."""

import numpy as np

from vic_drake.estimation.palpation import PalpationData
from vic_drake.tissue import hunt_crossley_force

SURFACE_Z_M = -0.05


def synthetic_palpation(
    *,
    kappa=4000.0,
    lam=20000.0,
    beta=1.35,
    mass_kg=0.081,
    lag_s=0.0,
    noise_N=0.0,
    freq_hz=1.5,
    duration_s=12.0,
    eps_mean_m=0.008,
    eps_amp_m=0.002,
    jitter_s=2e-4,
    seed=0,
):
    """Sinusoidal palpation of an HC tissue as the rig would log it.

    The sensor reads F_tissue - m z_ddot, late by ``lag_s``, with white noise;
    timestamps are 2 ms apart with uniform jitter of +-``jitter_s``.
    """
    rng = np.random.default_rng(seed)
    n = int(duration_s / 0.002)
    t = 0.002 * np.arange(n) + rng.uniform(-jitter_s, jitter_s, n)
    t[0] = 0.0
    w = 2 * np.pi * freq_hz

    def eps_of(tt):
        return eps_mean_m + eps_amp_m * np.sin(w * tt)

    def force_of(tt):
        eps = eps_of(tt)
        eps_dot = eps_amp_m * w * np.cos(w * tt)
        z_ddot = eps_amp_m * w**2 * np.sin(w * tt)  # z = s - eps.
        return hunt_crossley_force(eps, eps_dot, kappa, lam, beta) - mass_kg * z_ddot

    force = force_of(t - lag_s) + noise_N * rng.standard_normal(n)
    return PalpationData(
        t_s=t, z_m=SURFACE_Z_M - eps_of(t), force_N=force, surface_z_m=SURFACE_Z_M
    )


def polynomial_palpation(force_fn, n=2000, dt=0.002):
    """Uniform samples of a cubic z(t) (Savitzky-Golay derivatives are exact)."""
    t = dt * np.arange(n)
    T = t[-1]
    eps = 0.002 + 0.006 * (t / T) + 0.003 * (t / T) ** 2 - 0.002 * (t / T) ** 3
    eps_dot = (0.006 + 0.006 * (t / T) - 0.006 * (t / T) ** 2) / T
    eps_ddot = (0.006 - 0.012 * (t / T)) / T**2
    force = force_fn(eps, eps_dot, eps_ddot)
    return PalpationData(
        t_s=t, z_m=SURFACE_Z_M - eps, force_N=force, surface_z_m=SURFACE_Z_M
    )
