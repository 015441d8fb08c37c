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
"""

from vic_drake.experiments.campaign_params import CampaignParams
from vic_drake.experiments.compare_real import compare_real
from vic_drake.experiments.indenter_bank import IndenterBank, MakeIndenterDiagram
from vic_drake.experiments.map_pipeline import (
    PAPER_REGION_SIZE_M,
    MapPipelineResult,
    default_region,
    run_map_pipeline,
)
from vic_drake.experiments.palpation_campaign import (
    CampaignResult,
    grid_points,
    run_campaign,
)
from vic_drake.experiments.palpation_fit import PointFit, campaign_lag, fit_point
from vic_drake.experiments.palpation_sim import SimulatedPalpation, simulate_palpations
from vic_drake.experiments.paper_scenarios import (
    DISTURBANCE_DELAYS_S,
    REAL_EXPERIMENTS,
    disturbance_lifts,
    load_diagram,
    paper_scenarios,
    real_experiment_scenario,
    scan_start_s,
    synthetic_scenario,
    write_paper_scenarios,
)
from vic_drake.experiments.real_logs import (
    CF_FDCC_Z_GAINS,
    CS_FDCC_Z_GAINS,
    DEFAULT_CF_FORCE_N,
    DEFAULT_CS_STIFFNESS_N_PER_M,
    DEFAULT_R,
    FZI_DEFAULT_FDCC_Z_GAINS,
    MODEL_LOOP_GAIN_PER_KP,
    PAPER_FDCC_Z_GAINS,
    REAL_SCAN_FORCE_DELAY_S,
    WAYPOINT_PERIOD_S,
    detect_controller,
    fit_target_profile,
    identify_fdcc_z_gains,
    scenario_from_real_log,
)
from vic_drake.experiments.scan_diagram import (
    CommandedTipKinematics,
    MakeScanDiagram,
    initial_joint_positions,
    load_scenario_phantom,
    set_initial_state,
)
from vic_drake.experiments.scan_logs import (
    LOG_GROUPS,
    LogGroup,
    ScanLogs,
    logs_to_frame,
)
from vic_drake.experiments.scan_run import ScanResult, run_scan

__all__ = [
    "CF_FDCC_Z_GAINS",
    "CS_FDCC_Z_GAINS",
    "DEFAULT_CF_FORCE_N",
    "DEFAULT_CS_STIFFNESS_N_PER_M",
    "DEFAULT_R",
    "DISTURBANCE_DELAYS_S",
    "FZI_DEFAULT_FDCC_Z_GAINS",
    "LOG_GROUPS",
    "MODEL_LOOP_GAIN_PER_KP",
    "PAPER_FDCC_Z_GAINS",
    "PAPER_REGION_SIZE_M",
    "REAL_EXPERIMENTS",
    "REAL_SCAN_FORCE_DELAY_S",
    "WAYPOINT_PERIOD_S",
    "CampaignParams",
    "CampaignResult",
    "CommandedTipKinematics",
    "IndenterBank",
    "LogGroup",
    "MakeIndenterDiagram",
    "MakeScanDiagram",
    "MapPipelineResult",
    "PointFit",
    "ScanLogs",
    "ScanResult",
    "SimulatedPalpation",
    "campaign_lag",
    "compare_real",
    "default_region",
    "detect_controller",
    "disturbance_lifts",
    "fit_point",
    "fit_target_profile",
    "grid_points",
    "identify_fdcc_z_gains",
    "initial_joint_positions",
    "load_scenario_phantom",
    "logs_to_frame",
    "paper_scenarios",
    "real_experiment_scenario",
    "run_campaign",
    "run_map_pipeline",
    "run_scan",
    "scan_start_s",
    "scenario_from_real_log",
    "set_initial_state",
    "simulate_palpations",
    "synthetic_scenario",
    "load_diagram",
    "write_paper_scenarios",
]
