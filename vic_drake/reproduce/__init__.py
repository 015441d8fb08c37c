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

The names below are imported on first use (PEP 562), so that importing a
light submodule (:mod:`~vic_drake.reproduce.stage_names`, for the command
line's help) does not import the pipeline, pandas and pyarrow.
"""

from __future__ import annotations

from vic_drake.lazy_exports import lazy_exports

#: Public name -> the module that defines it.
_EXPORTS = {
    "CONTROLLERS": "vic_drake.paper",
    "DISTURBANCE_CONTROLLERS": "vic_drake.paper",
    "RunContext": "vic_drake.reproduce.context",
    "StageRecord": "vic_drake.reproduce.context",
    "StageSkipped": "vic_drake.reproduce.context",
    "ReproduceOptions": "vic_drake.reproduce.options",
    "STAGE_NAMES": "vic_drake.reproduce.stage_names",
    "STAGES": "vic_drake.reproduce.pipeline",
    "ReproduceResult": "vic_drake.reproduce.pipeline",
    "reproduce": "vic_drake.reproduce.pipeline",
    "run_pipeline": "vic_drake.reproduce.pipeline",
    "gather_claim_inputs": "vic_drake.reproduce.stages.claims",
    "REAL_CF_REFERENCE_N": "vic_drake.reproduce.stages.real_scans",
    "REAL_LIMITS": "vic_drake.reproduce.stages.real_scans",
    "REAL_SCAN_LOGS": "vic_drake.reproduce.stages.real_scans",
    "real_scan_frame": "vic_drake.reproduce.stages.real_scans",
    "replay_scan": "vic_drake.reproduce.stages.replay",
    "scan_limits": "vic_drake.reproduce.stages.scans",
    "scan_scenario": "vic_drake.reproduce.stages.scans",
}

__all__ = sorted(_EXPORTS)


__getattr__, __dir__ = lazy_exports(globals(), _EXPORTS)
