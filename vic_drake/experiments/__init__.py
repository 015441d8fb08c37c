"""Builders and runners of the paper's experiments, on Drake.

- :mod:`~vic_drake.experiments.scan_logs`: the signals a scan logs
  (:data:`LOG_GROUPS`), their one log (:class:`ScanLogs`) and the canonical
  DataFrame (:func:`logs_to_frame`).
- :mod:`~vic_drake.experiments.scan_diagram`: the closed-loop scan diagram
  (:func:`MakeScanDiagram`) and its initial state.
- :mod:`~vic_drake.experiments.scan_run`: simulating a scan
  (:func:`run_scan`, :class:`ScanResult`).
- :mod:`~vic_drake.experiments.real_logs`: scenarios of the real scan logs
  (:func:`scenario_from_real_log`) and the settings read from them.
- :mod:`~vic_drake.experiments.paper_scenarios`: the scenarios of
  ``diagrams/`` (:func:`paper_scenarios`, :func:`synthetic_scenario`).
- :mod:`~vic_drake.experiments.compare_real`: a real scan replayed and
  compared with its log (:func:`compare_real`).
- :mod:`~vic_drake.experiments.indenter_bank`: n palpating indenters in one
  diagram (:func:`MakeIndenterDiagram`).
- :mod:`~vic_drake.experiments.campaign_params`,
  :mod:`~vic_drake.experiments.palpation_sim`,
  :mod:`~vic_drake.experiments.palpation_fit`,
  :mod:`~vic_drake.experiments.palpation_campaign`: the simulated palpation
  campaign (:func:`run_campaign`).
- :mod:`~vic_drake.experiments.map_pipeline`: campaign, surface and GP maps,
  comparison with the truth (:func:`run_map_pipeline`).

The names below are imported from their modules on first use (PEP 562):
importing one module of the package, or the package, does not import the
others (every experiment at once took ~2 s).
:func:`~vic_drake.experiments.compare_real.compare_real` and
:func:`~vic_drake.experiments.paper_scenarios.paper_scenarios` are imported
from their modules: the package's ``compare_real`` and ``paper_scenarios``
are those modules.
"""

from __future__ import annotations

from vic_drake.lazy_exports import lazy_exports

#: Each exported name and the module of the package that defines it.
_EXPORTS = {
    "CampaignParams": "campaign_params",
    "IndenterBank": "indenter_bank",
    "MakeIndenterDiagram": "indenter_bank",
    "PAPER_REGION_SIZE_M": "map_pipeline",
    "MapPipelineResult": "map_pipeline",
    "default_region": "map_pipeline",
    "run_map_pipeline": "map_pipeline",
    "CampaignResult": "palpation_campaign",
    "grid_points": "palpation_campaign",
    "run_campaign": "palpation_campaign",
    "PointFit": "palpation_fit",
    "campaign_lag": "palpation_fit",
    "fit_point": "palpation_fit",
    "SimulatedPalpation": "palpation_sim",
    "simulate_palpations": "palpation_sim",
    "DISTURBANCE_DELAYS_S": "paper_scenarios",
    "REAL_EXPERIMENTS": "paper_scenarios",
    "disturbance_lifts": "paper_scenarios",
    "load_diagram": "paper_scenarios",
    "real_experiment_scenario": "paper_scenarios",
    "scan_start_s": "paper_scenarios",
    "synthetic_scenario": "paper_scenarios",
    "write_paper_scenarios": "paper_scenarios",
    "CF_FDCC_Z_GAINS": "real_logs",
    "CS_FDCC_Z_GAINS": "real_logs",
    "DEFAULT_CF_FORCE_N": "real_logs",
    "DEFAULT_CS_STIFFNESS_N_PER_M": "real_logs",
    "DEFAULT_R": "real_logs",
    "FZI_DEFAULT_FDCC_Z_GAINS": "real_logs",
    "MODEL_LOOP_GAIN_PER_KP": "real_logs",
    "PAPER_FDCC_Z_GAINS": "real_logs",
    "REAL_SCAN_FORCE_DELAY_S": "real_logs",
    "WAYPOINT_PERIOD_S": "real_logs",
    "detect_controller": "real_logs",
    "fit_target_profile": "real_logs",
    "identify_fdcc_z_gains": "real_logs",
    "scenario_from_real_log": "real_logs",
    "CommandedTipKinematics": "scan_diagram",
    "MakeScanDiagram": "scan_diagram",
    "initial_joint_positions": "scan_diagram",
    "load_scenario_phantom": "scan_diagram",
    "set_initial_state": "scan_diagram",
    "LOG_GROUPS": "scan_logs",
    "LogGroup": "scan_logs",
    "ScanLogs": "scan_logs",
    "logs_to_frame": "scan_logs",
    "ScanResult": "scan_run",
    "run_scan": "scan_run",
}

__all__ = list(_EXPORTS)


__getattr__, __dir__ = lazy_exports(
    globals(), {name: f"{__name__}.{module}" for name, module in _EXPORTS.items()}
)
