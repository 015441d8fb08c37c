"""Running an online estimator sample by sample over recorded arrays.

:func:`estimator_functions` picks the pure (initial state, step) pair of a
method; :func:`run_online` feeds it a whole log tick by tick, exactly as a
controller would, and times every tick. Comparison with a reference
(:func:`relative_errors`, :func:`convergence_time_s`) lives here too, so
the replay command and the tests score the same way.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online.core import OUTPUT_FIELDS
from vic_drake.estimation.online.ekf import (
    ekf_initial_state,
    ekf_slope_initial_state,
    ekf_slope_step,
    ekf_step,
)
from vic_drake.estimation.online.params import OnlineEstimatorParams
from vic_drake.estimation.online.rls import rls_initial_state, rls_step

#: Relative error within which an estimate counts as converged.
CONVERGENCE_REL_TOL = 0.10


def estimator_functions(params: OnlineEstimatorParams):
    """(initial_state(params), step(state, t, z, z_dot, force, surface_z, params))."""
    params.validate()
    if params.method == "rls":
        return rls_initial_state, rls_step
    if params.surface_from_slope:
        return ekf_slope_initial_state, ekf_slope_step
    return ekf_initial_state, ekf_step


@dataclass(frozen=True)
class OnlineTrace:
    """The estimator's outputs at every sample of a log.

    Attributes:
        t_s: (n,) sample times, s.
        values: (n, 6) outputs, columns :data:`OUTPUT_FIELDS`.
        tick_s: (n,) wall time of each step call, s.
        final_state: the state after the last sample.
    """

    t_s: np.ndarray
    values: np.ndarray
    tick_s: np.ndarray
    final_state: list

    def column(self, name: str) -> np.ndarray:
        return self.values[:, OUTPUT_FIELDS.index(name)]

    @property
    def kappa(self) -> np.ndarray:
        return self.column("kappa_hat")

    @property
    def lam(self) -> np.ndarray:
        return self.column("lambda_hat")

    @property
    def in_contact(self) -> np.ndarray:
        return self.column("in_contact") > 0.5

    @property
    def valid(self) -> np.ndarray:
        return self.column("valid") > 0.5


def run_online(
    t_s, z_m, z_dot_m_per_s, force_N, surface_z_m, params: OnlineEstimatorParams
) -> OnlineTrace:
    """Feeds every sample to the estimator in order.

    Args:
        t_s, z_m, z_dot_m_per_s, force_N: (n,) arrays (force positive =
            the body pushes the probe up). Non-finite values are passed on:
            the estimator must cope.
        surface_z_m: (n,) array or a float; NaN = unknown (latched at
            first contact).
        params: estimator settings (``method`` picks RLS or EKF).
    """
    t = np.asarray(t_s, float)
    n = t.size
    arrays = [np.asarray(a, float) for a in (z_m, z_dot_m_per_s, force_N)]
    surface = np.broadcast_to(np.asarray(surface_z_m, float), t.shape)
    for name, a in zip(("z_m", "z_dot_m_per_s", "force_N"), arrays):
        if a.shape != t.shape:
            raise VicDrakeError(
                f"run_online: {name} has shape {a.shape}; t_s has {t.shape}"
            )
    init, step = estimator_functions(params)
    state = init(params)
    values = np.empty((n, len(OUTPUT_FIELDS)))
    ticks = np.empty(n)
    rows = zip(t.tolist(), *(a.tolist() for a in arrays), surface.tolist(), strict=True)
    clock = time.perf_counter
    for k, (tk, zk, vk, fk, sk) in enumerate(rows):
        t0 = clock()
        state, est = step(state, tk, zk, vk, fk, sk, params)
        ticks[k] = clock() - t0
        values[k] = est
    return OnlineTrace(t_s=t, values=values, tick_s=ticks, final_state=state)


def relative_errors(estimate, reference, mask=None) -> np.ndarray:
    """|estimate - reference| / |reference| over the mask (finite pairs only)."""
    est = np.asarray(estimate, float)
    ref = np.broadcast_to(np.asarray(reference, float), est.shape)
    ok = np.isfinite(est) & np.isfinite(ref) & (ref != 0.0)
    if mask is not None:
        ok &= np.asarray(mask, bool)
    return np.abs(est[ok] - ref[ok]) / np.abs(ref[ok])


def convergence_time_s(
    t_s, estimate, reference, mask, *, tol: float = CONVERGENCE_REL_TOL
) -> float:
    """Time from the first masked sample until the estimate stays within tol.

    "Stays" over the masked samples (in contact, valid reference) from then
    to the end of the log. NaN if no masked sample, or if the last masked
    sample is still outside.
    """
    t = np.asarray(t_s, float)
    mask = np.asarray(mask, bool)
    est = np.asarray(estimate, float)[mask]
    ref = np.broadcast_to(np.asarray(reference, float), t.shape)[mask]
    tm = t[mask]
    if tm.size == 0:
        return float("nan")
    outside = ~(np.abs(est - ref) <= tol * np.abs(ref))
    if outside[-1]:
        return float("nan")
    if not outside.any():
        return 0.0
    last_out = int(np.flatnonzero(outside)[-1])
    return float(tm[last_out + 1] - tm[0])


__all__ = [
    "CONVERGENCE_REL_TOL",
    "OUTPUT_FIELDS",
    "OnlineTrace",
    "convergence_time_s",
    "estimator_functions",
    "relative_errors",
    "run_online",
]
