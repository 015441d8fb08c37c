"""Offline Hunt-Crossley and Kelvin-Voigt fits of sinusoidal palpations.

The paper's offline phase (Sec. II-A, III-A), one concept per module:

- :mod:`~vic_drake.estimation.palpation.data`: the log
  (:class:`PalpationData`), the lag shift, smoothed kinematics and the
  selection of the in-contact samples.
- :mod:`~vic_drake.estimation.palpation.fits`: least-squares Hunt-Crossley
  and Kelvin-Voigt fits at a fixed beta (paper eq. 4) and the relative
  residual.
- :mod:`~vic_drake.estimation.palpation.lag`: the sensor lag, found by fit
  quality.
- :mod:`~vic_drake.estimation.palpation.table_i`: the beta sweep and the model
  comparison of Table I.
- :mod:`~vic_drake.estimation.palpation.residual`: residual against
  palpation time (Fig. 3).

Pipeline used by ``vic-drake fit-palpation``:

1. :func:`estimate_lag`: the force sample of time t belongs to the position
   of time t - lag; found once per log.
2. :func:`shift` aligns the force with the position.
3. :func:`fit_hunt_crossley` / :func:`fit_kelvin_voigt` at fixed beta;
   :func:`sweep_beta` over [1.0, 2.0]; :func:`compare_models` (Table I).
4. :func:`residual_vs_palpation_time` (Fig. 3).
"""

from vic_drake.estimation.palpation.data import (
    DEFAULT_INDENTER_MASS_KG,
    DEFAULT_MIN_FORCE_N,
    DEFAULT_MIN_PENETRATION_M,
    DEFAULT_SPIKE_SIGMA,
    Kinematics,
    PalpationData,
    contact_mask,
    kinematics,
    shift,
    spike_mask,
)
from vic_drake.estimation.palpation.fits import (
    MIN_CONTACT_SAMPLES,
    HuntCrossleyFit,
    HuntCrossleyMassFit,
    KelvinVoigtFit,
    fit_hunt_crossley,
    fit_hunt_crossley_with_mass,
    fit_kelvin_voigt,
)
from vic_drake.estimation.palpation.lag import (
    DEFAULT_LAG_SETTLE_S,
    DEFAULT_MAX_LAG_S,
    LagProfile,
    estimate_lag,
    lag_profile,
)
from vic_drake.estimation.palpation.residual import (
    ExponentialFit,
    ResidualCurve,
    fit_exponential,
    residual_vs_palpation_time,
)
from vic_drake.estimation.palpation.table_i import (
    BETA_GRID_STEP,
    BETA_RANGE,
    PAPER_TABLE_I,
    BetaSweep,
    ModelComparison,
    compare_models,
    sweep_beta,
)

__all__ = [
    "BETA_GRID_STEP",
    "BETA_RANGE",
    "DEFAULT_INDENTER_MASS_KG",
    "DEFAULT_LAG_SETTLE_S",
    "DEFAULT_MAX_LAG_S",
    "DEFAULT_MIN_FORCE_N",
    "DEFAULT_MIN_PENETRATION_M",
    "DEFAULT_SPIKE_SIGMA",
    "MIN_CONTACT_SAMPLES",
    "PAPER_TABLE_I",
    "BetaSweep",
    "ExponentialFit",
    "HuntCrossleyFit",
    "HuntCrossleyMassFit",
    "KelvinVoigtFit",
    "Kinematics",
    "LagProfile",
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
    "residual_vs_palpation_time",
    "shift",
    "spike_mask",
    "sweep_beta",
]
