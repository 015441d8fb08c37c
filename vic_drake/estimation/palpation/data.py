"""A palpation log along z and the samples the fits use.

:class:`PalpationData` holds one palpation (or load test) as logged: tip
height z, tissue surface height s and the force of the tissue on the probe.
:func:`shift` pairs each force sample with the position of an earlier time
(the sensor lag), :func:`kinematics` gives the smoothed penetration
eps = s - z, its rate and the tip acceleration, and :func:`contact_mask`
selects the samples a fit uses.

Contact selection: a sample is used when eps > ``min_penetration_m`` (0.5 mm)
AND the measured force exceeds ``min_force_N`` (the real controller's contact
threshold, :data:`vic_drake.paper.CONTACT_THRESHOLD_N`) AND it is not a force
spike (a sample whose force departs from a 11-sample running median by more
than 8 robust standard deviations of that difference) AND no timestamp gap
lies within one derivative window.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import median_filter

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.signals import (
    DEFAULT_DERIVATIVE_WINDOW_S,
    gap_free_mask,
    median_period,
    smoothed_derivatives,
)
from vic_drake.paper import CONTACT_THRESHOLD_N

DEFAULT_INDENTER_MASS_KG = 0.081
"""m_I: mass below the sensing element of the BOTA SensONE, kg.

From the published robot description of the rig: the sensor's wrench-side
mass is 0.081 kg; the 3D-printed spherical indenter screwed to it is not
weighed there and is left out. The term m_I z_ddot is small against the
tissue force, but the lag search leans on it (see
:mod:`vic_drake.estimation.palpation.lag`; docs/decisions.md, "Indenter
mass").
"""

DEFAULT_MIN_PENETRATION_M = 0.5e-3
"""Penetration below which a sample is not fitted, m."""

DEFAULT_MIN_FORCE_N = CONTACT_THRESHOLD_N
"""Force below which a sample is not fitted, N: the contact threshold."""

DEFAULT_SPIKE_SIGMA = 8.0
"""Robust standard deviations that make a force sample a spike."""


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
