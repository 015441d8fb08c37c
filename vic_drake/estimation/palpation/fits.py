"""Least-squares Hunt-Crossley and Kelvin-Voigt fits at a fixed exponent.

The paper's estimation model (Sec. II-A, eqs. 2-4): with tip height z, surface
height s, penetration eps = s - z >= 0 and indenter mass m_I below the
force-sensing element,

    F_tissue = kappa eps^beta + lam eps^beta eps_dot        (eps_dot = s_dot - z_dot)
    F_sensor = F_tissue - m_I z_ddot

so that, at fixed beta, (kappa, lam) solve the linear least-squares problem

    F_sensor + m_I z_ddot = kappa eps^beta + lam eps^beta eps_dot

over the in-contact samples (:func:`~vic_drake.estimation.palpation.data.contact_mask`).
Here ``F_sensor`` is :attr:`PalpationData.force_N`, the force the probe feels
from the body (positive = body pushes the probe up, minus the sensor's z
reading). The Kelvin-Voigt alternative is ``k eps + d eps_dot`` with no force
offset (both models give zero force at zero penetration, as the paper's
Table I compares them).

Relative residual (``relative`` in every fit): RMS of the least-squares
residual divided by the RMS of the fitted target ``F_sensor + m_I z_ddot``
over the same samples, i.e. the residual as a fraction of the typical force.
The paper's Table I (:mod:`vic_drake.paper`) calls its numbers "relative
residual value [N]" without a definition; its values are of the same order
as ours but are not guaranteed to be the same quantity, so compare orderings,
not digits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation.data import (
    DEFAULT_INDENTER_MASS_KG,
    DEFAULT_MIN_FORCE_N,
    DEFAULT_MIN_PENETRATION_M,
    DEFAULT_SPIKE_SIGMA,
    PalpationData,
    contact_mask,
    kinematics,
)
from vic_drake.estimation.signals import DEFAULT_DERIVATIVE_WINDOW_S
from vic_drake.paper import BEST_BETA
from vic_drake.tissue.models import hunt_crossley_force, kelvin_voigt_force

MIN_CONTACT_SAMPLES = 200
"""In-contact samples a fit needs at least."""


@dataclass(frozen=True)
class HuntCrossleyFit:
    """kappa eps^beta + lam eps^beta eps_dot fitted by least squares.

    Attributes:
        kappa: elasticity, N/m^beta.
        lam: viscosity, N s/m^(beta+1).
        beta: the fixed exponent.
        rms_N: RMS residual over the fitted samples, N.
        relative: rms_N / RMS of the fitted target (see module docstring).
        n_samples: samples used.
        indenter_mass_kg: m_I used in the target F_sensor + m_I z_ddot.
    """

    kappa: float
    lam: float
    beta: float
    rms_N: float
    relative: float
    n_samples: int
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG

    def tissue_force(self, eps_m, eps_dot_m_per_s) -> np.ndarray:
        """Model tissue force, N (0 out of contact; not clipped)."""
        return hunt_crossley_force(
            eps_m, eps_dot_m_per_s, self.kappa, self.lam, self.beta
        )


@dataclass(frozen=True)
class KelvinVoigtFit:
    """k eps + d eps_dot fitted by least squares (no offset).

    Attributes:
        k: stiffness, N/m. d: damping, N s/m.
        rms_N, relative, n_samples, indenter_mass_kg: as in HuntCrossleyFit.
    """

    k: float
    d: float
    rms_N: float
    relative: float
    n_samples: int
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG

    def tissue_force(self, eps_m, eps_dot_m_per_s) -> np.ndarray:
        """Model tissue force, N (0 out of contact; not clipped)."""
        return kelvin_voigt_force(eps_m, eps_dot_m_per_s, self.k, self.d)


def _check_beta(beta) -> float:
    try:
        beta = float(beta)
    except (TypeError, ValueError):
        raise VicDrakeError(f"beta must be a number in (0, 3]; got {beta!r}") from None
    if not (0.0 < beta <= 3.0):
        raise VicDrakeError(f"beta must be in (0, 3]; got {beta!r}")
    return beta


def _check_mass(mass) -> float:
    mass = float(mass)
    if not (math.isfinite(mass) and mass >= 0.0):
        raise VicDrakeError(f"indenter_mass_kg must be finite and >= 0; got {mass!r}")
    return mass


@dataclass
class _Problem:
    """Everything the linear fits need, computed once per aligned log."""

    eps: np.ndarray
    eps_dot: np.ndarray
    z_ddot: np.ndarray
    force: np.ndarray
    mask: np.ndarray = field(repr=False)

    def target(self, mass: float) -> np.ndarray:
        return self.force[self.mask] + mass * self.z_ddot[self.mask]


def _problem(
    data: PalpationData,
    *,
    derivative_window_s: float,
    min_penetration_m: float,
    min_force_N: float,
    spike_sigma: float | None,
    sample_mask=None,
) -> _Problem:
    kin = kinematics(data, window_s=derivative_window_s)
    mask = contact_mask(
        data,
        kin,
        min_penetration_m=min_penetration_m,
        min_force_N=min_force_N,
        spike_sigma=spike_sigma,
    )
    p = _Problem(
        kin.eps_m, kin.eps_dot_m_per_s, kin.z_ddot_m_per_s2, data.force_N, mask
    )
    return _restrict(
        p, sample_mask, min_penetration_m=min_penetration_m, min_force_N=min_force_N
    )


def _restrict(
    p: _Problem, sample_mask, *, min_penetration_m: float, min_force_N: float
) -> _Problem:
    """``p`` on its samples that ``sample_mask`` keeps (None: all), with at
    least :data:`MIN_CONTACT_SAMPLES` of them (the thresholds name the
    contact rule in the error)."""
    mask = p.mask
    if sample_mask is not None:
        sample_mask = np.asarray(sample_mask, bool)
        if sample_mask.shape != mask.shape:
            raise VicDrakeError(
                f"sample_mask has shape {sample_mask.shape}; the log has {mask.shape}"
            )
        mask = mask & sample_mask
    n = int(mask.sum())
    if n < MIN_CONTACT_SAMPLES:
        raise VicDrakeError(
            f"only {n} in-contact samples (penetration > {min_penetration_m * 1e3:g} mm "
            f"and force > {min_force_N:g} N); a fit needs at least {MIN_CONTACT_SAMPLES}. "
            "Is this a palpation log with the probe pressed into the tissue?"
        )
    return p if mask is p.mask else replace(p, mask=mask)


def _hc_columns(p: _Problem, beta: float, mask=None) -> np.ndarray:
    mask = p.mask if mask is None else mask
    e = np.clip(p.eps[mask], 0.0, None) ** beta
    return np.column_stack([e, e * p.eps_dot[mask]])


def _kv_columns(p: _Problem, mask=None) -> np.ndarray:
    mask = p.mask if mask is None else mask
    return np.column_stack([p.eps[mask], p.eps_dot[mask]])


def _lstsq(A: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, float, float]:
    # Column scaling: eps^beta ~ 1e-3 and eps^beta eps_dot ~ 1e-5 differ a lot.
    scale = np.sqrt(np.mean(A**2, axis=0))
    scale[scale == 0.0] = 1.0
    coef, *_ = np.linalg.lstsq(A / scale, y, rcond=None)
    coef = coef / scale
    resid = y - A @ coef
    rms = float(np.sqrt(np.mean(resid**2)))
    rms_y = float(np.sqrt(np.mean(y**2)))
    return coef, rms, rms / rms_y if rms_y > 0 else math.inf


def _fit_hc(p: _Problem, beta: float, mass: float) -> HuntCrossleyFit:
    coef, rms, rel = _lstsq(_hc_columns(p, beta), p.target(mass))
    return HuntCrossleyFit(
        kappa=float(coef[0]),
        lam=float(coef[1]),
        beta=beta,
        rms_N=rms,
        relative=rel,
        n_samples=int(p.mask.sum()),
        indenter_mass_kg=mass,
    )


def _fit_kv(p: _Problem, mass: float) -> KelvinVoigtFit:
    coef, rms, rel = _lstsq(_kv_columns(p), p.target(mass))
    return KelvinVoigtFit(
        k=float(coef[0]),
        d=float(coef[1]),
        rms_N=rms,
        relative=rel,
        n_samples=int(p.mask.sum()),
        indenter_mass_kg=mass,
    )


def fit_hunt_crossley(
    data: PalpationData,
    beta: float = BEST_BETA,
    *,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
    sample_mask=None,
) -> HuntCrossleyFit:
    """Least-squares kappa, lam at fixed beta (paper eq. 4).

    Solves F + m_I z_ddot = kappa eps^beta + lam eps^beta eps_dot over the
    in-contact samples (see the module docstring). The data must already be
    aligned (:func:`~vic_drake.estimation.palpation.data.shift`); simulated
    data without sensor lag can be passed as is.

    Args:
        data: the palpation.
        beta: Hunt-Crossley exponent, in (0, 3].
        indenter_mass_kg: m_I, kg (>= 0).
        derivative_window_s: Savitzky-Golay window for z_dot, z_ddot, s.
        min_penetration_m, min_force_N, spike_sigma: contact selection.
        sample_mask: optional (n,) bool, further restricts the samples (e.g.
            a time window).

    Returns:
        HuntCrossleyFit.

    Raises:
        VicDrakeError: bad beta or mass, or fewer than
            :data:`MIN_CONTACT_SAMPLES` in-contact samples.
    """
    beta = _check_beta(beta)
    mass = _check_mass(indenter_mass_kg)
    p = _problem(
        data,
        derivative_window_s=derivative_window_s,
        min_penetration_m=min_penetration_m,
        min_force_N=min_force_N,
        spike_sigma=spike_sigma,
        sample_mask=sample_mask,
    )
    return _fit_hc(p, beta, mass)


def fit_kelvin_voigt(
    data: PalpationData,
    *,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
    sample_mask=None,
) -> KelvinVoigtFit:
    """Least-squares k, d of F + m_I z_ddot = k eps + d eps_dot (no offset).

    Same samples and arguments as :func:`fit_hunt_crossley`.
    """
    mass = _check_mass(indenter_mass_kg)
    p = _problem(
        data,
        derivative_window_s=derivative_window_s,
        min_penetration_m=min_penetration_m,
        min_force_N=min_force_N,
        spike_sigma=spike_sigma,
        sample_mask=sample_mask,
    )
    return _fit_kv(p, mass)


@dataclass(frozen=True)
class HuntCrossleyMassFit:
    """kappa, lam and m_I fitted together (3-column least squares)."""

    fit: HuntCrossleyFit
    indenter_mass_kg: float


def fit_hunt_crossley_with_mass(
    data: PalpationData,
    beta: float = BEST_BETA,
    *,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
) -> HuntCrossleyMassFit:
    """Estimates m_I with kappa and lam: F = kappa e^b + lam e^b eps_dot - m_I z_ddot.

    At one palpation frequency z_ddot is nearly proportional to -eps, so m_I
    trades off against kappa, and against the sensor lag (a lag tau adds an
    inertia-like k tau^2 / 2, see :mod:`vic_drake.estimation.palpation.lag`):
    the estimate is only meaningful on aligned data with an independently
    known lag and rich motion (it recovers m_I on such synthetic logs). On the
    real logs it is not independent of
    :func:`~vic_drake.estimation.palpation.lag.estimate_lag`, which assumes m_I.
    """
    beta = _check_beta(beta)
    p = _problem(
        data,
        derivative_window_s=derivative_window_s,
        min_penetration_m=min_penetration_m,
        min_force_N=min_force_N,
        spike_sigma=spike_sigma,
    )
    A = np.column_stack([_hc_columns(p, beta), -p.z_ddot[p.mask]])
    coef, _, _ = _lstsq(A, p.force[p.mask])
    mass = float(coef[2])
    y = p.target(mass)
    resid = y - _hc_columns(p, beta) @ coef[:2]
    rms = float(np.sqrt(np.mean(resid**2)))
    fit = HuntCrossleyFit(
        kappa=float(coef[0]),
        lam=float(coef[1]),
        beta=beta,
        rms_N=rms,
        relative=rms / float(np.sqrt(np.mean(y**2))),
        n_samples=int(p.mask.sum()),
        indenter_mass_kg=mass,
    )
    return HuntCrossleyMassFit(fit=fit, indenter_mass_kg=mass)
