"""The paper, end to end: offline estimation, scans, disturbance, claims, report.

The pipeline is a list of stages (:mod:`vic_drake.reproduce.pipeline`). Each
stage is a function ``stage(ctx) -> value`` (one module each under
:mod:`vic_drake.reproduce.stages`) that reads the results of earlier stages
from the :class:`RunContext` and returns its own; a stage that fails is
recorded, not fatal, and the claims that need it are reported as not
evaluated, with the reason.

Stages (see :data:`STAGES`):

- ``offline_real``: Table I, beta sweep, residual vs palpation time and load
  test on the paper's palpation logs (when the data is there).
- ``offline_sim``: the same fits on palpations simulated on the phantom.
- ``map``: palpation campaign on a grid, surface fit and GP maps of kappa and
  lambda; rib detection on the estimated and on the measured map.
- ``scans``: the four controllers (CS, CF, VS-CF, VS-VF) nominal, and VS-VF,
  CS, CF with the phantom lifted and lowered; every log written as parquet
  with its scenario YAML beside it.
- ``real_scans``: the paper's scan logs reduced to the same metrics.
- ``compare_real``: (full mode) each real scan re-run in simulation on the
  measured map and compared with its log.
- ``online``: the online kappa/lambda estimators (RLS, EKF) replayed tick by
  tick over the paper's palpation and VS scan logs and this run's simulated
  VS-VF scan.
- ``claims``: C1-C7 (:mod:`vic_drake.analysis.claims`) -> ``claims.json``.
- ``replay``: a Meshcat recording of one scan -> ``replay.html``.
- ``report``: ``report.html`` (:mod:`vic_drake.reproduce.report`; figures
  from :mod:`vic_drake.reproduce.plots`).

:func:`reproduce` is the library entry point; ``vic-drake reproduce`` is a
thin wrapper.
"""

from vic_drake.paper import CONTROLLERS, DISTURBANCE_CONTROLLERS
from vic_drake.reproduce.context import RunContext, StageRecord, StageSkipped
from vic_drake.reproduce.options import ReproduceOptions
from vic_drake.reproduce.pipeline import (
    STAGE_NAMES,
    STAGES,
    ReproduceResult,
    reproduce,
    run_pipeline,
)
from vic_drake.reproduce.stages.claims import gather_claim_inputs
from vic_drake.reproduce.stages.real_scans import (
    REAL_CF_REFERENCE_N,
    REAL_LIMITS,
    REAL_SCAN_LOGS,
    real_scan_frame,
)
from vic_drake.reproduce.stages.replay import replay_scan
from vic_drake.reproduce.stages.scans import scan_limits, scan_scenario

__all__ = [
    "CONTROLLERS",
    "DISTURBANCE_CONTROLLERS",
    "REAL_CF_REFERENCE_N",
    "REAL_LIMITS",
    "REAL_SCAN_LOGS",
    "ReproduceOptions",
    "ReproduceResult",
    "RunContext",
    "STAGES",
    "STAGE_NAMES",
    "StageRecord",
    "StageSkipped",
    "gather_claim_inputs",
    "real_scan_frame",
    "replay_scan",
    "reproduce",
    "run_pipeline",
    "scan_limits",
    "scan_scenario",
]
