"""Load/unload test (Fig. 2): palpation-fitted models predict a load cycle.

Kelvin-Voigt and Hunt-Crossley parameters are fitted on a sinusoidal
palpation (the pipeline of
:func:`vic_drake.estimation.palpation.table_i.compare_models`: lag,
alignment, least squares) and then predict the force of a constant-velocity
load test from its measured tip trajectory alone:

    F_pred = F_tissue(eps, eps_dot) - m_I z_ddot,

with F_tissue clipped at zero (tissue cannot pull the probe). The load
test's force is aligned with the palpation's lag (same sensor chain). The
error is the RMS of F_measured - F_pred over the samples where the probe is
in the tissue (eps > 0) or the sensor reads more than the contact threshold,
so a model is charged both for missing force and for inventing it (force
spikes and samples next to timestamp gaps are left out, as in the fits).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation.data import (
    DEFAULT_INDENTER_MASS_KG,
    DEFAULT_MIN_FORCE_N,
    PalpationData,
    kinematics,
    shift,
    spike_mask,
)
from vic_drake.estimation.palpation.fits import (
    HuntCrossleyFit,
    KelvinVoigtFit,
    _check_beta,
    fit_hunt_crossley,
    fit_kelvin_voigt,
)
from vic_drake.estimation.palpation.lag import DEFAULT_MAX_LAG_S, estimate_lag
from vic_drake.estimation.signals import DEFAULT_DERIVATIVE_WINDOW_S
from vic_drake.paper import BEST_BETA

MIN_LOAD_SAMPLES = 50

#: Target speed above which a load test's target counts as moving, m/s (the
#: logged ramps run at 10-30 mm/s).
MIN_TARGET_SPEED_M_PER_S = 1e-3

#: The phases of a load test, in time order (see :func:`load_test_phases`).
LOAD_TEST_PHASES = ("load", "hold", "unload", "release")


def load_test_phases(t_s, z_target_m) -> dict | None:
    """Splits a load test by its target: {phase: (n,) bool}, or None.

    The phases (:data:`LOAD_TEST_PHASES`): ``load`` up to the end of the
    target's descent, ``hold`` until the target starts to rise, ``unload``
    while it rises, ``release`` after it stops (the tip, held by a compliant
    controller, is still leaving the tissue). None when the target does not
    descend once and then rise once (a palpation, or a log without target).
    """
    t = np.asarray(t_s, float)
    if z_target_m is None or t.size < 3:
        return None
    rate = np.gradient(np.asarray(z_target_m, float), t)
    down = np.flatnonzero(rate < -MIN_TARGET_SPEED_M_PER_S)
    up = np.flatnonzero(rate > MIN_TARGET_SPEED_M_PER_S)
    if down.size == 0 or up.size == 0 or up[0] <= down[-1]:
        return None
    if np.any(np.diff(down) > 1) or np.any(np.diff(up) > 1):
        return None  # More than one descent or rise: not a load cycle.
    t_load, t_rise, t_top = t[down[-1]], t[up[0]], t[up[-1]]
    return {
        "load": t <= t_load,
        "hold": (t > t_load) & (t < t_rise),
        "unload": (t >= t_rise) & (t <= t_top),
        "release": t > t_top,
    }


def predict_force(
    fit: HuntCrossleyFit | KelvinVoigtFit,
    data: PalpationData,
    *,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
) -> np.ndarray:
    """Force the sensor would read (PalpationData.force_N convention), N.

    F_tissue(eps, eps_dot) clipped at 0, minus m_I z_ddot, from the measured
    tip trajectory of ``data`` (its force is not used).
    """
    kin = kinematics(data, window_s=derivative_window_s)
    tissue = np.maximum(fit.tissue_force(kin.eps_m, kin.eps_dot_m_per_s), 0.0)
    return tissue - fit.indenter_mass_kg * kin.z_ddot_m_per_s2


@dataclass(frozen=True)
class LoadTestResult:
    """Measured and predicted force of a load test.

    Attributes:
        t_s: (n,) timestamps of the aligned load test, s.
        measured_N: (n,) measured force (lag removed), N.
        kelvin_voigt_N, hunt_crossley_N: (n,) predictions, N.
        mask: (n,) samples the RMS errors are taken over.
        kelvin_voigt_rms_N, hunt_crossley_rms_N: RMS prediction errors, N.
        beta: Hunt-Crossley exponent.
        lag_s: lag removed from both logs, s.
        kelvin_voigt, hunt_crossley: the palpation fits used.
    """

    t_s: np.ndarray
    measured_N: np.ndarray
    kelvin_voigt_N: np.ndarray
    hunt_crossley_N: np.ndarray
    mask: np.ndarray
    kelvin_voigt_rms_N: float
    hunt_crossley_rms_N: float
    beta: float
    lag_s: float
    kelvin_voigt: KelvinVoigtFit
    hunt_crossley: HuntCrossleyFit
    penetration_m: np.ndarray | None = None


def check_roles(
    load: PalpationData,
    palpation: PalpationData,
    *,
    load_name: str = "the load test",
    palpation_name: str = "the palpation",
) -> None:
    """Refuses a load test whose logged target is not a load cycle, or a
    palpation whose logged target is one (the two swapped), by
    :func:`load_test_phases`. A log without a target is not checked.

    Raises:
        VicDrakeError: naming the log (``load_name``, ``palpation_name``)
            and what it should be.
    """

    def is_cycle(data: PalpationData) -> bool:
        return load_test_phases(data.t_s, data.z_target_m) is not None

    load_ok = load.z_target_m is None or is_cycle(load)
    palpation_is_cycle = palpation.z_target_m is not None and is_cycle(palpation)
    if not load_ok:
        swap = (
            f" (the two look swapped: {palpation_name} is the load/unload test)"
            if palpation_is_cycle
            else ""
        )
        raise VicDrakeError(
            f"{load_name} is not a load/unload test: its target does not descend "
            f"once and rise once (a palpation's goes up and down){swap}"
        )
    if palpation_is_cycle:
        raise VicDrakeError(
            f"{palpation_name} is a load/unload test, not a palpation: the models "
            "are fitted on a sinusoidal palpation (e.g. palpation/test_soft_1hz)"
        )


def load_test(
    load: PalpationData,
    palpation: PalpationData,
    *,
    beta: float = BEST_BETA,
    lag_s: float | None = None,
    max_lag_s: float = DEFAULT_MAX_LAG_S,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    progress=None,
    load_name: str = "the load test",
    palpation_name: str = "the palpation",
) -> LoadTestResult:
    """Fits KV and HC on ``palpation`` and predicts the ``load`` test.

    Args:
        load: the load/unload log as recorded.
        palpation: the palpation log the parameters are fitted on, as recorded.
        beta: Hunt-Crossley exponent.
        lag_s: sensor lag; None estimates it on the palpation.
        max_lag_s: lag search range.
        indenter_mass_kg: m_I for both fit and prediction.
        progress: optional callable(str).
        load_name, palpation_name: the two logs as the errors name them.

    Raises:
        VicDrakeError: bad beta, the logs' roles swapped or wrong
            (:func:`check_roles`), too few in-contact samples in either log.
    """
    say = progress or (lambda _msg: None)
    beta = _check_beta(beta)
    check_roles(load, palpation, load_name=load_name, palpation_name=palpation_name)
    if lag_s is None:
        say("estimating the sensor lag on the palpation")
        lag_s = estimate_lag(
            palpation,
            max_lag_s,
            indenter_mass_kg=indenter_mass_kg,
            derivative_window_s=derivative_window_s,
        )
    kw = dict(
        indenter_mass_kg=indenter_mass_kg, derivative_window_s=derivative_window_s
    )
    say("fitting Kelvin-Voigt and Hunt-Crossley on the palpation")
    aligned_palpation = shift(palpation, lag_s)
    kv = fit_kelvin_voigt(aligned_palpation, **kw)
    hc = fit_hunt_crossley(aligned_palpation, beta, **kw)
    say("predicting the load test")
    aligned = shift(load, lag_s)
    kin = kinematics(aligned, window_s=derivative_window_s)
    mask = (kin.eps_m > 0.0) | (aligned.force_N > DEFAULT_MIN_FORCE_N)
    mask &= spike_mask(aligned.force_N)
    if kin.valid is not None:
        mask &= kin.valid
    if mask.sum() < MIN_LOAD_SAMPLES:
        raise VicDrakeError(
            f"the load test has only {int(mask.sum())} samples in contact "
            f"(penetration > 0 or force > {DEFAULT_MIN_FORCE_N:g} N); needs "
            f"at least {MIN_LOAD_SAMPLES}"
        )
    f_kv = predict_force(kv, aligned, derivative_window_s=derivative_window_s)
    f_hc = predict_force(hc, aligned, derivative_window_s=derivative_window_s)

    def rms(pred):
        return float(np.sqrt(np.mean((aligned.force_N[mask] - pred[mask]) ** 2)))

    return LoadTestResult(
        t_s=aligned.t_s,
        measured_N=aligned.force_N,
        kelvin_voigt_N=f_kv,
        hunt_crossley_N=f_hc,
        mask=mask,
        kelvin_voigt_rms_N=rms(f_kv),
        hunt_crossley_rms_N=rms(f_hc),
        beta=beta,
        lag_s=float(lag_s),
        kelvin_voigt=kv,
        hunt_crossley=hc,
        penetration_m=kin.eps_m,
    )
