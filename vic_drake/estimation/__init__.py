"""Offline estimation of tissue parameters from palpation logs.

Public names of the palpation fits and the load test; the surface fit and
the GP maps are imported from their own modules. This layer is pure
fitting math: the simulated palpation campaign that feeds it lives in
:mod:`vic_drake.experiments`.
"""

from vic_drake.estimation.loadtest import LoadTestResult, load_test, predict_force
from vic_drake.estimation.palpation import (
    DEFAULT_INDENTER_MASS_KG,
    DEFAULT_MAX_LAG_S,
    BetaSweep,
    ExponentialFit,
    HuntCrossleyFit,
    KelvinVoigtFit,
    Kinematics,
    LagProfile,
    ModelComparison,
    PalpationData,
    ResidualCurve,
    compare_models,
    contact_mask,
    estimate_lag,
    fit_exponential,
    fit_hunt_crossley,
    fit_hunt_crossley_with_mass,
    fit_kelvin_voigt,
    kinematics,
    lag_profile,
    residual_vs_palpation_time,
    shift,
    sweep_beta,
)
from vic_drake.estimation.signals import (
    DEFAULT_DERIVATIVE_WINDOW_S,
    shift_signal,
    smoothed_derivatives,
)

__all__ = [
    "DEFAULT_DERIVATIVE_WINDOW_S",
    "DEFAULT_INDENTER_MASS_KG",
    "DEFAULT_MAX_LAG_S",
    "BetaSweep",
    "ExponentialFit",
    "HuntCrossleyFit",
    "KelvinVoigtFit",
    "Kinematics",
    "LagProfile",
    "LoadTestResult",
    "ModelComparison",
    "PalpationData",
    "ResidualCurve",
    "compare_models",
    "contact_mask",
    "estimate_lag",
    "fit_exponential",
    "fit_hunt_crossley",
    "fit_hunt_crossley_with_mass",
    "fit_kelvin_voigt",
    "kinematics",
    "lag_profile",
    "load_test",
    "predict_force",
    "residual_vs_palpation_time",
    "shift",
    "shift_signal",
    "smoothed_derivatives",
    "sweep_beta",
]
