"""Online estimation of the tissue's Hunt-Crossley parameters during a scan.

The paper's first item of future work: kappa and lam estimated tick by tick
from the probe's motion and the sensor force, instead of a separate
palpation campaign.

- :mod:`~vic_drake.estimation.online.params`: :class:`OnlineEstimatorParams`.
- :mod:`~vic_drake.estimation.online.core`: state layout, contact, surface,
  faults, the scalar Kalman update.
- :mod:`~vic_drake.estimation.online.rls`: recursive least squares with
  forgetting at fixed beta.
- :mod:`~vic_drake.estimation.online.ekf`: EKF with a random-walk state
  (kappa, lam, optionally the surface offset and beta).
- :mod:`~vic_drake.estimation.online.slope`: the penetration, hence the
  surface, from the tissue's local slope under a dithered tip (the EKF's
  surface with ``surface_from_slope``);
  :mod:`~vic_drake.estimation.online.slope_gram` and
  :mod:`~vic_drake.estimation.online.slope_instrument` its least-squares
  and its instrumented (the dither as the instrument) solves.
- :mod:`~vic_drake.estimation.online.replay`: run over a recorded log,
  compare with a reference.
"""

from vic_drake.estimation.online.core import OUTPUT_FIELDS, Estimate
from vic_drake.estimation.online.ekf import ekf_initial_state, ekf_layout, ekf_step
from vic_drake.estimation.online.params import ONLINE_METHODS, OnlineEstimatorParams
from vic_drake.estimation.online.replay import (
    CONVERGENCE_REL_TOL,
    OnlineTrace,
    convergence_time_s,
    estimator_functions,
    relative_errors,
    run_online,
)
from vic_drake.estimation.online.rls import RLS_SIZE, rls_initial_state, rls_step

__all__ = [
    "CONVERGENCE_REL_TOL",
    "ONLINE_METHODS",
    "OUTPUT_FIELDS",
    "RLS_SIZE",
    "Estimate",
    "OnlineEstimatorParams",
    "OnlineTrace",
    "convergence_time_s",
    "ekf_initial_state",
    "ekf_layout",
    "ekf_step",
    "estimator_functions",
    "relative_errors",
    "rls_initial_state",
    "rls_step",
    "run_online",
]
