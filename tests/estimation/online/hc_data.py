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


#: The tissue of the slope-fit tests: kappa, lam, beta; their sample time, s.
SLOPE_KAPPA, SLOPE_LAM, SLOPE_BETA = 6000.0, 40000.0, 1.35
SLOPE_DT = 0.002


def softening_under_a_still_tip(*, seed=0, noise_N=0.045):
    """3 s dithered at 6 mm on a flat surface, then the tip still (a
    saturated stiffness stops it); from 3.5 s (the fit's window has no
    dither left) kappa falls to 0.6 x over 1 s.
    (t, z, z_dot, force, kappa)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 6.0, SLOPE_DT)
    w = 2.0 * np.pi * 3.0
    on = t < 3.0
    eps = 0.006 + np.where(on, 3e-4 * np.sin(w * t), 0.0)
    eps_dot = np.where(on, 3e-4 * w * np.cos(w * t), 0.0)
    kappa = SLOPE_KAPPA * (1.0 - 0.4 * np.clip(t - 3.5, 0.0, 1.0))
    force = (kappa + SLOPE_LAM * eps_dot) * eps**SLOPE_BETA
    force = force + rng.normal(0.0, noise_N, t.size)
    return t, 0.1 - eps, -eps_dot, force, kappa
