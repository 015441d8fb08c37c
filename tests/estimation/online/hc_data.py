"""Simulated Hunt-Crossley palpations for the online estimator tests."""

import numpy as np


def hc_palpation(kappa, lam, *, beta=1.35, seed=0, duration_s=10.0, noise_N=0.05):
    """A 1.5 Hz palpation of a flat surface at 0.1 m: (t, z, z_dot, force, s)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration_s, 0.002)
    s = 0.1
    eps = 0.006 - 0.003 * np.cos(2 * np.pi * 1.5 * t)  # at rest at t = 0
    eps_dot = 0.003 * 2 * np.pi * 1.5 * np.sin(2 * np.pi * 1.5 * t)
    force = (kappa + lam * eps_dot) * eps**beta + rng.normal(0.0, noise_N, t.size)
    return t, s - eps, -eps_dot, force, s
