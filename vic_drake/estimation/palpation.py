"""Offline Hunt-Crossley and Kelvin-Voigt fits of sinusoidal palpations.

The paper's estimation model (Sec. II-A, eqs. 2-4): with tip height z, surface
height s, penetration eps = s - z >= 0 and indenter mass m_I below the
force-sensing element,

    F_tissue = kappa eps^beta + lam eps^beta eps_dot        (eps_dot = s_dot - z_dot)
    F_sensor = F_tissue - m_I z_ddot

so that, at fixed beta, (kappa, lam) solve the linear least-squares problem

    F_sensor + m_I z_ddot = kappa eps^beta + lam eps^beta eps_dot

over the in-contact samples. Here ``F_sensor`` is :attr:`PalpationData.force_N`,
the force the probe feels from the body (positive = body pushes the probe up,
minus the sensor's z reading). The Kelvin-Voigt alternative is
``k eps + d eps_dot`` with no force offset (both models give zero force at
zero penetration, as the paper's Table I compares them).

Pipeline used by ``vic-drake fit-palpation``:

1. :func:`estimate_lag`: the force sample of time t belongs to the position
   of time t - lag. The lag is a property of the sensor chain, so it is found
   once per log: each force sample is paired with the (smoothed) kinematics
   one candidate lag earlier, on a grid of one sample period over
   [0, max_lag_s], the reference model (Hunt-Crossley at beta = 1.35, the
   paper's choice, with the stated m_I) is refitted, and the lag with the
   smallest RMS residual wins (Brent refinement between grid neighbours).
   The approach transient (first second of contact) is left out of this
   search. All models are then compared at that one lag.

   What identifies the lag: to first order a time shift of the force is a
   phase lead that the viscous term absorbs (lag and lam trade off), to
   second order it adds tau^2/2 F_ddot, an inertia-like term of about
   k_lin tau^2 / 2 kg that the fixed m_I cannot absorb. The search thus finds
   the lag at which the data are consistent with the known indenter mass;
   refitting m_I as a free parameter leaves the residual nearly flat in lag.
   The signal grows with the palpation frequency squared: on the shared
   logs the residual stays within 1 % of its minimum over 0-40 ms at 1 Hz,
   36-42 ms at 2 Hz and 50-52 ms at 2.5 Hz (the real controller later used
   28 ticks = 56 ms). :func:`lag_profile` exposes the curve.
2. :func:`shift` aligns the force with the position.
3. :func:`fit_hunt_crossley` / :func:`fit_kelvin_voigt` at fixed beta;
   :func:`sweep_beta` over [1.0, 2.0]; :func:`compare_models` (Table I).
4. :func:`residual_vs_palpation_time` (Fig. 3).

Relative residual (``relative`` in every fit): RMS of the least-squares
residual divided by the RMS of the fitted target ``F_sensor + m_I z_ddot``
over the same samples, i.e. the residual as a fraction of the typical force.
The paper's Table I calls its numbers "relative residual value [N]" without
a definition; its values (0.066 KV, 0.029 / 0.014 / 0.045 at beta = 1.5 /
1.35 / 1.1) are of the same order as ours but are not guaranteed to be the
same quantity, so compare orderings, not digits.

Contact selection: a sample is used when eps > ``min_penetration_m`` (0.5 mm)
AND the measured force exceeds ``min_force_N`` (0.5 N, the real controller's
contact threshold) AND it is not a force spike (a sample whose force departs
from a 11-sample running median by more than 8 robust standard deviations of
that difference).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.ndimage import median_filter
from scipy.optimize import minimize_scalar

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.signals import (
    DEFAULT_DERIVATIVE_WINDOW_S,
    gap_free_mask,
    median_period,
    smoothed_derivatives,
)

DEFAULT_BETA = 1.35
"""The paper's chosen Hunt-Crossley exponent (Sec. III-A)."""

DEFAULT_INDENTER_MASS_KG = 0.081
"""m_I: mass below the sensing element of the BOTA SensONE, kg.

From the published robot description of the rig: the sensor's wrench-side
mass is 0.081 kg; the 3D-printed spherical indenter screwed to it is not
weighed there and is left out (a few grams of PLA). The term m_I z_ddot is
small on these logs (|z_ddot| < 1 m/s^2, so < 0.1 N against 4-9 N of
tissue force), but the lag search leans on it (module docstring): with
m_I = 0, 0.081, 0.3 kg the 2 Hz log gives 36.7, 38.6, 43.4 ms.
"""

DEFAULT_MIN_PENETRATION_M = 0.5e-3
DEFAULT_MIN_FORCE_N = 0.5
DEFAULT_MAX_LAG_S = 0.2
DEFAULT_SPIKE_SIGMA = 8.0
DEFAULT_LAG_SETTLE_S = 1.0
"""Approach transient left out of the lag search, s (see :func:`lag_profile`)."""
MIN_CONTACT_SAMPLES = 200
BETA_RANGE = (1.0, 2.0)
BETA_GRID_STEP = 0.05


def _as_1d(name: str, value, n: int | None = None) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim != 1:
        raise VicDrakeError(f"PalpationData.{name} must be 1-D; got shape {arr.shape}")
    if n is not None and arr.size != n:
        raise VicDrakeError(f"PalpationData.{name} has {arr.size} samples; t_s has {n}")
    if not np.all(np.isfinite(arr)):
        raise VicDrakeError(f"PalpationData.{name} has non-finite values")
    return arr


@dataclass(frozen=True)
class PalpationData:
    """One palpation (or load test) along z.

    Attributes:
        t_s: (n,) increasing timestamps, s.
        z_m: (n,) tip height in the robot base frame, m.
        force_N: (n,) force of the tissue on the probe along +z, N: POSITIVE
            when the body pushes the probe up (minus the sensor's z force).
        surface_z_m: tissue surface height, m: a float or an (n,) array.
        z_target_m: (n,) commanded tip height, m, or None.
    """

    t_s: np.ndarray
    z_m: np.ndarray
    force_N: np.ndarray
    surface_z_m: float | np.ndarray
    z_target_m: np.ndarray | None = None

    def __post_init__(self):
        t = _as_1d("t_s", self.t_s)
        if t.size < 2:
            raise VicDrakeError(f"PalpationData needs >= 2 samples; got {t.size}")
        median_period(t)  # Raises on non-increasing timestamps.
        object.__setattr__(self, "t_s", t)
        object.__setattr__(self, "z_m", _as_1d("z_m", self.z_m, t.size))
        object.__setattr__(self, "force_N", _as_1d("force_N", self.force_N, t.size))
        s = np.asarray(self.surface_z_m, dtype=float)
        if s.ndim == 0:
            if not np.isfinite(s):
                raise VicDrakeError("PalpationData.surface_z_m is not finite")
            object.__setattr__(self, "surface_z_m", float(s))
        else:
            object.__setattr__(self, "surface_z_m", _as_1d("surface_z_m", s, t.size))
        if self.z_target_m is not None:
            object.__setattr__(
                self, "z_target_m", _as_1d("z_target_m", self.z_target_m, t.size)
            )

    @classmethod
    def from_frame(cls, df) -> PalpationData:
        """From the 6-column bag layout of :func:`vic_drake.realdata.read_bag`.

        Columns t_s, surface_z_m, z_target_m, z_m, force_z_N (sensor reading,
        negative = pressing; negated here). A constant surface column becomes
        a float. Rows with non-finite values and repeated or out-of-order
        timestamps are dropped (an error if fewer than half remain).
        """
        needed = ("t_s", "surface_z_m", "z_target_m", "z_m", "force_z_N")
        missing = [c for c in needed if c not in df.columns]
        if missing:
            layout = df.attrs.get("layout", "unknown")
            raise VicDrakeError(
                f"a palpation log needs columns {list(needed)} (the 6-column "
                f"palpation/loadcycle layout); this one ({layout!r} layout) lacks "
                f"{missing}"
            )
        rows = df[list(needed)].to_numpy(float)
        # Tolerate a few corrupt rows: non-finite values, repeated or
        # out-of-order timestamps (kept: finite rows in time order, first of
        # each timestamp).
        rows = rows[np.all(np.isfinite(rows), axis=1)]
        rows = rows[np.argsort(rows[:, 0], kind="stable")]
        if rows.shape[0]:
            rows = rows[np.concatenate([[True], np.diff(rows[:, 0]) > 0.0])]
        if rows.shape[0] < max(2, 0.5 * len(df)):
            raise VicDrakeError(
                f"a palpation log needs finite rows with increasing timestamps; only "
                f"{rows.shape[0]} of {len(df)} rows are usable"
            )
        t, surface, z_target, z, force_sensor = rows.T
        if np.ptp(surface) == 0.0:
            surface = float(surface[0])
        return cls(
            t_s=t,
            z_m=z,
            force_N=-force_sensor,
            surface_z_m=surface,
            z_target_m=z_target,
        )

    @property
    def n(self) -> int:
        return int(self.t_s.size)

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1] - self.t_s[0])

    @property
    def surface_array_m(self) -> np.ndarray:
        """Surface height at every sample, (n,), m."""
        return np.broadcast_to(np.asarray(self.surface_z_m, float), self.t_s.shape)

    @property
    def penetration_m(self) -> np.ndarray:
        """eps = s - z, (n,), m (negative out of contact)."""
        return self.surface_array_m - self.z_m

    def select(self, mask) -> PalpationData:
        """The samples where ``mask`` is True (keeps their timestamps)."""
        mask = np.asarray(mask, bool)
        surface = self.surface_z_m
        if not np.isscalar(surface):
            surface = surface[mask]
        return PalpationData(
            t_s=self.t_s[mask],
            z_m=self.z_m[mask],
            force_N=self.force_N[mask],
            surface_z_m=surface,
            z_target_m=None if self.z_target_m is None else self.z_target_m[mask],
        )


def shift(data: PalpationData, lag_s: float) -> PalpationData:
    """Aligns force with position when the force lags by ``lag_s`` seconds.

    Each force sample, logged at t, is paired with the position of time
    t - lag_s: the returned log has timestamps t - lag_s, the logged forces
    untouched, and z (surface, target) linearly interpolated at t - lag_s.
    Interpolating the smooth position rather than the noisy force keeps the
    force noise intact, so residuals at different lags stay comparable
    (interpolating the force would average its noise at fractional lags and
    bias a fit-quality lag search). Samples with t - lag_s before the first
    timestamp are dropped. ``lag_s = 0`` returns ``data``.
    """
    lag_s = float(lag_s)
    if not math.isfinite(lag_s):
        raise VicDrakeError(f"lag_s must be finite; got {lag_s!r}")
    if lag_s == 0.0:
        return data
    t_new = data.t_s - lag_s
    keep = (t_new >= data.t_s[0]) & (t_new <= data.t_s[-1])
    if keep.sum() < 2:
        raise VicDrakeError(
            f"a lag of {lag_s} s leaves fewer than 2 samples of a {data.duration_s:.3f} s log"
        )
    t_new = t_new[keep]
    surface = data.surface_z_m
    if not np.isscalar(surface):
        surface = np.interp(t_new, data.t_s, surface)
    return PalpationData(
        t_s=t_new,
        z_m=np.interp(t_new, data.t_s, data.z_m),
        force_N=data.force_N[keep],
        surface_z_m=surface,
        z_target_m=(
            None
            if data.z_target_m is None
            else np.interp(t_new, data.t_s, data.z_target_m)
        ),
    )


@dataclass(frozen=True)
class Kinematics:
    """Smoothed penetration and its rates at every sample of a log.

    Attributes:
        eps_m: s - z (smoothed z), m.
        eps_dot_m_per_s: s_dot - z_dot, m/s.
        z_ddot_m_per_s2: tip acceleration, m/s^2.
        valid: True where no timestamp gap lies within one filter window
            (see :func:`vic_drake.estimation.signals.gap_free_mask`).
    """

    eps_m: np.ndarray
    eps_dot_m_per_s: np.ndarray
    z_ddot_m_per_s2: np.ndarray
    valid: np.ndarray | None = None


def kinematics(
    data: PalpationData, *, window_s: float = DEFAULT_DERIVATIVE_WINDOW_S
) -> Kinematics:
    """Penetration, penetration rate and tip acceleration (Savitzky-Golay).

    See :mod:`vic_drake.estimation.signals` for the filter and window.
    """
    z, z_dot, z_ddot = smoothed_derivatives(data.t_s, data.z_m, window_s=window_s)
    if np.isscalar(data.surface_z_m):
        s, s_dot = data.surface_z_m, 0.0
    else:
        s, s_dot, _ = smoothed_derivatives(
            data.t_s, data.surface_z_m, window_s=window_s
        )
    return Kinematics(
        eps_m=s - z,
        eps_dot_m_per_s=s_dot - z_dot,
        z_ddot_m_per_s2=z_ddot,
        valid=gap_free_mask(data.t_s, window_s),
    )


def spike_mask(
    force_N, *, sigma: float = DEFAULT_SPIKE_SIGMA, width: int = 11
) -> np.ndarray:
    """True where the force is not an isolated spike (see module docstring)."""
    force_N = np.asarray(force_N, float)
    if force_N.size < width:
        return np.ones(force_N.shape, bool)
    deviation = force_N - median_filter(force_N, size=width, mode="nearest")
    mad = np.median(np.abs(deviation - np.median(deviation)))
    scale = 1.4826 * mad
    if scale <= 0.0:
        return np.ones(force_N.shape, bool)
    return np.abs(deviation) <= sigma * scale


def contact_mask(
    data: PalpationData,
    kin: Kinematics | None = None,
    *,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
) -> np.ndarray:
    """Samples used by the fits: in contact and not a force spike."""
    eps = data.penetration_m if kin is None else kin.eps_m
    mask = (eps > min_penetration_m) & (data.force_N > min_force_N)
    if kin is not None and kin.valid is not None:
        mask &= kin.valid
    if spike_sigma is not None:
        mask &= spike_mask(data.force_N, sigma=spike_sigma)
    return mask


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
        from vic_drake.tissue.models import hunt_crossley_force

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
        from vic_drake.tissue.models import kelvin_voigt_force

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
    if sample_mask is not None:
        sample_mask = np.asarray(sample_mask, bool)
        if sample_mask.shape != mask.shape:
            raise VicDrakeError(
                f"sample_mask has shape {sample_mask.shape}; the log has {mask.shape}"
            )
        mask &= sample_mask
    n = int(mask.sum())
    if n < MIN_CONTACT_SAMPLES:
        raise VicDrakeError(
            f"only {n} in-contact samples (penetration > {min_penetration_m * 1e3:g} mm "
            f"and force > {min_force_N:g} N); a fit needs at least {MIN_CONTACT_SAMPLES}. "
            "Is this a palpation log with the probe pressed into the tissue?"
        )
    return _Problem(
        kin.eps_m, kin.eps_dot_m_per_s, kin.z_ddot_m_per_s2, data.force_N, mask
    )


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
    beta: float = DEFAULT_BETA,
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
    aligned (:func:`shift`); simulated data without sensor lag can be passed
    as is.

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
    beta: float = DEFAULT_BETA,
    *,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
) -> HuntCrossleyMassFit:
    """Estimates m_I with kappa and lam: F = kappa e^b + lam e^b eps_dot - m_I z_ddot.

    At one palpation frequency z_ddot is nearly proportional to -eps, so m_I
    trades off against kappa, and against the sensor lag (a lag tau adds an
    inertia-like k tau^2 / 2, see the module docstring): the estimate is only
    meaningful on aligned data with an independently known lag and rich
    motion (it recovers m_I on such synthetic logs). On the real logs it is
    not independent of :func:`estimate_lag`, which assumes m_I.
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


# ---------------------------------------------------------------------------
# Sensor lag.


@dataclass(frozen=True)
class LagProfile:
    """RMS residual of the reference fit for each candidate lag.

    Attributes:
        lags_s: (k,) candidate lags, s. rms_N: (k,) RMS residual, N.
        lag_s: the refined minimiser. beta: reference exponent used.
    """

    lags_s: np.ndarray
    rms_N: np.ndarray
    lag_s: float
    beta: float

    def flat_range(self, tolerance: float = 0.01) -> tuple[float, float]:
        """Lags whose residual is within ``tolerance`` (relative) of the best.

        A wide range means the lag is poorly identified by this log (see the
        module docstring); the contiguous range around the minimiser is given.
        """
        limit = (1.0 + tolerance) * float(np.min(self.rms_N))
        best = int(np.argmin(self.rms_N))
        lo = hi = best
        while lo > 0 and self.rms_N[lo - 1] <= limit:
            lo -= 1
        while hi < self.rms_N.size - 1 and self.rms_N[hi + 1] <= limit:
            hi += 1
        return float(self.lags_s[lo]), float(self.lags_s[hi])


def lag_profile(
    data: PalpationData,
    max_lag_s: float = DEFAULT_MAX_LAG_S,
    *,
    beta: float = DEFAULT_BETA,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
    settle_s: float = DEFAULT_LAG_SETTLE_S,
) -> LagProfile:
    """Reference-fit RMS residual over lags 0, dt, 2 dt, ... max_lag_s.

    For each candidate the force samples are paired with the smoothed
    kinematics ``lag`` earlier (as :func:`shift` does), the contact samples
    are reselected and Hunt-Crossley at ``beta`` is refitted.
    Force samples in the first ``max_lag_s`` of the log are left out for
    every candidate, so all candidates are scored on the same force samples
    (the contact test on penetration still follows the lag).

    The approach is left out too: force samples within ``settle_s`` of the
    first pressing sample (force > ``min_force_N``), capped at a quarter of
    the in-contact time. The rig's palpations start at the surface and sink
    to the working depth over the first cycle while the tissue relaxes, which
    Hunt-Crossley does not model; on the shared 1 Hz log that transient
    alone moves the minimiser from ~30 ms to 0 (the 2 and 2.5 Hz logs move
    by < 2 ms).
    """
    max_lag_s = float(max_lag_s)
    if not (math.isfinite(max_lag_s) and max_lag_s >= 0.0):
        raise VicDrakeError(f"max_lag_s must be finite and >= 0; got {max_lag_s!r}")
    if max_lag_s > 0.5 * data.duration_s:
        raise VicDrakeError(
            f"max_lag_s = {max_lag_s} s is more than half the {data.duration_s:.3f} s log"
        )
    beta = _check_beta(beta)
    mass = _check_mass(indenter_mass_kg)
    dt = median_period(data.t_s)
    lags = dt * np.arange(int(np.floor(max_lag_s / dt + 1e-9)) + 1)
    kin = kinematics(data, window_s=derivative_window_s)
    # Force samples whose position is inside the log for every candidate.
    span = data.t_s >= data.t_s[0] + max_lag_s
    if spike_sigma is not None:
        span &= spike_mask(data.force_N, sigma=spike_sigma)
    span &= data.force_N > min_force_N
    if settle_s > 0.0 and span.any():
        pressing = data.t_s[data.force_N > min_force_N]
        settle = min(float(settle_s), 0.25 * (pressing[-1] - pressing[0]))
        span &= data.t_s >= pressing[0] + settle

    def score(lag: float) -> float:
        t_pos = data.t_s - lag
        eps = np.interp(t_pos, data.t_s, kin.eps_m)
        mask = span & (eps > min_penetration_m)
        mask &= np.interp(t_pos, data.t_s, kin.valid.astype(float)) > 0.999
        n = int(mask.sum())
        if n < MIN_CONTACT_SAMPLES:
            raise VicDrakeError(
                f"only {n} in-contact samples (penetration > "
                f"{min_penetration_m * 1e3:g} mm and force > {min_force_N:g} N); "
                f"a fit needs at least {MIN_CONTACT_SAMPLES}"
            )
        p = _Problem(
            eps,
            np.interp(t_pos, data.t_s, kin.eps_dot_m_per_s),
            np.interp(t_pos, data.t_s, kin.z_ddot_m_per_s2),
            data.force_N,
            mask,
        )
        return _fit_hc(p, beta, mass).rms_N

    rms = np.array([score(lag) for lag in lags])
    best = int(np.argmin(rms))
    lag = float(lags[best])
    if lags.size > 1:
        # Continuous refinement between the grid neighbours (Brent).
        lo, hi = lags[max(best - 1, 0)], lags[min(best + 1, lags.size - 1)]
        res = minimize_scalar(
            score, bounds=(lo, hi), method="bounded", options={"xatol": 1e-5}
        )
        if res.fun < rms[best]:
            lag = float(res.x)
    return LagProfile(lags_s=lags, rms_N=rms, lag_s=lag, beta=beta)


def estimate_lag(
    data: PalpationData,
    max_lag_s: float = DEFAULT_MAX_LAG_S,
    *,
    beta: float = DEFAULT_BETA,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    settle_s: float = DEFAULT_LAG_SETTLE_S,
) -> float:
    """Sensor lag of the force behind the position, s (>= 0).

    The lag in [0, max_lag_s] minimising the RMS residual of the reference
    Hunt-Crossley fit (see :func:`lag_profile` and the module docstring).
    """
    return lag_profile(
        data,
        max_lag_s,
        beta=beta,
        indenter_mass_kg=indenter_mass_kg,
        derivative_window_s=derivative_window_s,
        settle_s=settle_s,
    ).lag_s


# ---------------------------------------------------------------------------
# Beta sweep and model comparison (Table I).


@dataclass(frozen=True)
class BetaSweep:
    """Hunt-Crossley fits over a grid of beta.

    Attributes:
        betas: (k,) grid. rms_N, relative: (k,) residuals per beta.
        best_beta: refined minimiser of rms_N in the grid's range.
        best_fit: the fit at best_beta.
    """

    betas: np.ndarray
    rms_N: np.ndarray
    relative: np.ndarray
    best_beta: float
    best_fit: HuntCrossleyFit


def sweep_beta(
    data: PalpationData,
    betas=None,
    *,
    refine: bool = True,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    min_penetration_m: float = DEFAULT_MIN_PENETRATION_M,
    min_force_N: float = DEFAULT_MIN_FORCE_N,
    spike_sigma: float | None = DEFAULT_SPIKE_SIGMA,
) -> BetaSweep:
    """Fits Hunt-Crossley for each beta (default 1.0, 1.05, ..., 2.0).

    With ``refine`` the grid minimiser is polished by a bounded scalar
    search (Brent, xatol 1e-4) between its grid neighbours.
    """
    if betas is None:
        lo, hi = BETA_RANGE
        betas = np.round(np.arange(lo, hi + 0.5 * BETA_GRID_STEP, BETA_GRID_STEP), 10)
    betas = np.array([_check_beta(b) for b in np.atleast_1d(betas)])
    mass = _check_mass(indenter_mass_kg)
    p = _problem(
        data,
        derivative_window_s=derivative_window_s,
        min_penetration_m=min_penetration_m,
        min_force_N=min_force_N,
        spike_sigma=spike_sigma,
    )
    fits = [_fit_hc(p, b, mass) for b in betas]
    rms = np.array([f.rms_N for f in fits])
    rel = np.array([f.relative for f in fits])
    best = int(np.argmin(rms))
    best_fit = fits[best]
    if refine and betas.size >= 3:
        order = np.sort(betas)
        k = int(np.searchsorted(order, betas[best]))
        lo = order[max(k - 1, 0)]
        hi = order[min(k + 1, order.size - 1)]
        if hi > lo:
            res = minimize_scalar(
                lambda b: _fit_hc(p, float(b), mass).rms_N,
                bounds=(lo, hi),
                method="bounded",
                options={"xatol": 1e-4},
            )
            candidate = _fit_hc(p, float(res.x), mass)
            if candidate.rms_N < best_fit.rms_N:
                best_fit = candidate
    return BetaSweep(
        betas=betas, rms_N=rms, relative=rel, best_beta=best_fit.beta, best_fit=best_fit
    )


@dataclass(frozen=True)
class ModelComparison:
    """Table I: Kelvin-Voigt and Hunt-Crossley at several beta on one log.

    Attributes:
        lag_s: the lag removed before fitting, s.
        kelvin_voigt: the KV fit.
        hunt_crossley: beta -> HC fit (in the order given).
        sweep: the beta sweep over [1.0, 2.0], or None.
        lag_profile: the lag search, or None when the lag was given.
    """

    lag_s: float
    kelvin_voigt: KelvinVoigtFit
    hunt_crossley: dict[float, HuntCrossleyFit]
    sweep: BetaSweep | None = None
    lag_profile: LagProfile | None = None

    @property
    def best_beta(self) -> float | None:
        return None if self.sweep is None else self.sweep.best_beta


TABLE_I_BETAS = (1.1, 1.35, 1.5)
"""The exponents of the paper's Table I."""

PAPER_TABLE_I = {"kelvin_voigt": 0.066, 1.5: 0.029, 1.35: 0.014, 1.1: 0.045}
"""The paper's Table I "relative residual value" (for plots next to ours)."""


def compare_models(
    data: PalpationData,
    betas=TABLE_I_BETAS,
    *,
    lag_s: float | None = None,
    max_lag_s: float = DEFAULT_MAX_LAG_S,
    sweep: bool = True,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    progress=None,
) -> ModelComparison:
    """Lag estimation, alignment, KV and HC fits, beta sweep, on a raw log.

    Args:
        data: the palpation as logged (force lagging position).
        betas: exponents to report.
        lag_s: the lag to remove; None estimates it (:func:`estimate_lag`).
        max_lag_s: lag search range [0, max_lag_s].
        sweep: also run :func:`sweep_beta` over [1.0, 2.0].
        progress: optional callable(str) for progress messages.
    """
    say = progress or (lambda _msg: None)
    betas = [_check_beta(b) for b in betas]
    profile = None
    if lag_s is None:
        say(f"estimating the sensor lag over [0, {max_lag_s:g}] s")
        profile = lag_profile(
            data,
            max_lag_s,
            indenter_mass_kg=indenter_mass_kg,
            derivative_window_s=derivative_window_s,
        )
        lag_s = profile.lag_s
    aligned = shift(data, lag_s)
    kw = dict(
        indenter_mass_kg=indenter_mass_kg, derivative_window_s=derivative_window_s
    )
    say("fitting Kelvin-Voigt and Hunt-Crossley")
    kv = fit_kelvin_voigt(aligned, **kw)
    hc = {b: fit_hunt_crossley(aligned, b, **kw) for b in betas}
    result_sweep = None
    if sweep:
        say("sweeping beta over [1.0, 2.0]")
        result_sweep = sweep_beta(aligned, **kw)
    return ModelComparison(
        lag_s=float(lag_s),
        kelvin_voigt=kv,
        hunt_crossley=hc,
        sweep=result_sweep,
        lag_profile=profile,
    )


# ---------------------------------------------------------------------------
# Residual against palpation time (Fig. 3).


@dataclass(frozen=True)
class ExponentialFit:
    """r(t) = a exp(-t / tau_s) + c."""

    a: float
    tau_s: float
    c: float

    def __call__(self, t_s) -> np.ndarray:
        return self.a * np.exp(-np.asarray(t_s, float) / self.tau_s) + self.c


@dataclass(frozen=True)
class ResidualCurve:
    """Residual of fits on growing windows, evaluated on the whole log.

    Attributes:
        window_s: (k,) palpation times (window lengths from the first
            in-contact sample), s.
        relative: (k,) relative residual on all in-contact samples of the log
            of the parameters fitted on the window.
        rms_N: (k,) the same as an RMS, N.
        kappa, lam: (k,) parameters fitted on each window.
        exp_fit: exponential fit of relative vs window_s, or None if it
            failed to converge.
        beta: exponent used.
    """

    window_s: np.ndarray
    relative: np.ndarray
    rms_N: np.ndarray
    kappa: np.ndarray
    lam: np.ndarray
    exp_fit: ExponentialFit | None
    beta: float


def fit_exponential(t_s, r, *, min_tau_s: float | None = None) -> ExponentialFit | None:
    """Robust least squares of r(t) = a exp(-t/tau) + c.

    Soft-L1 loss (scale: a tenth of the spread of r), so a few windows that
    happen to generalise unusually well or badly (e.g. one holding only the
    approach transient) do not bend the curve; tau is bounded below by
    ``min_tau_s`` (default: the smallest t, since a decay faster than the
    first sample is not resolved by the data).

    Returns:
        The fit, or None with fewer than 4 points or no convergence.
    """
    from scipy.optimize import least_squares

    t_s = np.asarray(t_s, float)
    r = np.asarray(r, float)
    if t_s.size < 4 or not np.all(np.isfinite(r)):
        return None
    min_tau = float(t_s.min() if min_tau_s is None else min_tau_s)
    min_tau = max(min_tau, 1e-6)
    order = np.argsort(t_s)
    quarter = max(t_s.size // 4, 1)
    c0 = float(np.median(r[order[-quarter:]]))
    a0 = float(np.median(r[order[:quarter]]) - c0)
    if a0 == 0.0:
        a0 = 1e-12
    tau0 = float(max((t_s.max() - t_s.min()) / 5.0, min_tau * 1.01))
    spread = float(np.ptp(r))
    if spread == 0.0:
        return ExponentialFit(a=0.0, tau_s=tau0, c=float(r[0]))

    def resid(x):
        a, tau, c = x
        return a * np.exp(-t_s / tau) + c - r

    res = least_squares(
        resid,
        x0=(a0, tau0, c0),
        bounds=([-np.inf, min_tau, -np.inf], [np.inf, np.inf, np.inf]),
        loss="soft_l1",
        f_scale=0.1 * spread,
        x_scale=(max(abs(a0), 1e-12), tau0, max(abs(c0), 1e-12)),
        max_nfev=20000,
    )
    if not res.success:
        return None
    a, tau, c = res.x
    return ExponentialFit(a=float(a), tau_s=float(tau), c=float(c))


def residual_vs_palpation_time(
    data: PalpationData,
    windows_s=None,
    *,
    beta: float = DEFAULT_BETA,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
) -> ResidualCurve:
    """Relative residual against palpation time (Fig. 3 of the paper).

    For each window length T, kappa and lam are fitted on the in-contact
    samples within T seconds of the first in-contact sample; the residual of
    those parameters is then evaluated on ALL in-contact samples of the log
    (relative residual as defined in the module docstring). Short windows
    generalise worse, and the curve falls towards the whole-log fit's
    residual, so more palpation time helps, as in the paper. The data must
    already be aligned (:func:`shift`).

    Args:
        windows_s: window lengths, s; default 0.5 s to the whole log (0.5 s
            steps up to 10 s, then 2 s steps).
    """
    beta = _check_beta(beta)
    mass = _check_mass(indenter_mass_kg)
    p = _problem(
        data,
        derivative_window_s=derivative_window_s,
        min_penetration_m=DEFAULT_MIN_PENETRATION_M,
        min_force_N=DEFAULT_MIN_FORCE_N,
        spike_sigma=DEFAULT_SPIKE_SIGMA,
    )
    t_contact = data.t_s - data.t_s[np.argmax(p.mask)]
    total = float(t_contact[p.mask][-1])
    if windows_s is None:
        windows_s = np.concatenate(
            [
                np.arange(0.5, min(total, 10.0), 0.5),
                np.arange(10.0, total, 2.0),
                [total],
            ]
        )
    windows_s = np.unique(np.asarray(windows_s, float))
    if windows_s.size == 0 or not np.all(windows_s > 0):
        raise VicDrakeError(f"windows_s must be positive lengths; got {windows_s!r}")
    A_all = _hc_columns(p, beta)
    y_all = p.target(mass)
    rms_y = float(np.sqrt(np.mean(y_all**2)))
    t_masked = t_contact[p.mask]
    out = {"window": [], "rel": [], "rms": [], "kappa": [], "lam": []}
    for T in windows_s:
        sel = t_masked <= T
        if sel.sum() < 10:
            continue
        coef, _, _ = _lstsq(A_all[sel], y_all[sel])
        rms = float(np.sqrt(np.mean((y_all - A_all @ coef) ** 2)))
        out["window"].append(float(T))
        out["rel"].append(rms / rms_y)
        out["rms"].append(rms)
        out["kappa"].append(float(coef[0]))
        out["lam"].append(float(coef[1]))
    if not out["window"]:
        raise VicDrakeError("no window holds enough in-contact samples to fit")
    window = np.array(out["window"])
    rel = np.array(out["rel"])
    return ResidualCurve(
        window_s=window,
        relative=rel,
        rms_N=np.array(out["rms"]),
        kappa=np.array(out["kappa"]),
        lam=np.array(out["lam"]),
        exp_fit=fit_exponential(window, rel),
        beta=beta,
    )
