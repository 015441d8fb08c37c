"""Where a real phantom's surface lay against the map, from what a scan log holds.

Two readings of a canonical scan frame, neither using the force of the scan
proper (:func:`vic_drake.analysis.contact.scan_window` opens 1 s after the
first contact):

- :func:`first_contact_offset`: the tissue's own surface where the probe
  first touched it, from a free-space approach. Before the first contact the
  force is the sensor's bias; from the touch on, Hunt-Crossley gives
  ``(F - bias)^(1/beta) = c (s - z)`` with ``c`` constant while the tip
  descends at a steady speed, so the line through ``(z, (F - bias)^(1/beta))``
  over the onset meets zero at the surface ``s``, whatever kappa, lambda or
  the speed. The offset is ``s`` minus the map's surface there.
- :func:`controller_map_offset`: how far the surface the real controller
  used (31-column logs: tip height plus its logged penetration) lay above the
  map. That is the controller's belief (its own copy of the map), not a
  measurement of the tissue.

A log that starts in contact (the 9-column CS/CF logs) carries neither
(:mod:`vic_drake.experiments.surface_calibration` then falls back on the
rig's default, :data:`vic_drake.realdata.RIG_SURFACE_OFFSET_M`).
"""

from typing import NamedTuple

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import require_columns
from vic_drake.analysis.contact import pressing_force_N
from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTACT_THRESHOLD_N

#: Free-space record needed before the first contact, s: the force's bias and
#: noise are read over it.
MIN_FREE_S = 0.2
#: The free-space samples end this long before the first sample over the
#: contact threshold, s (the force rises from the bias before it gets there).
FREE_MARGIN_S = 0.2
#: The onset fit starts where the force exceeds the bias by this many
#: sigmas of its noise, and by at least ONSET_LOW_N.
ONSET_NOISE_Z = 4.0
ONSET_LOW_N = 0.2
#: ... and ends where it first exceeds the bias by this much, N (the tip is
#: still descending at about its approach speed there).
ONSET_HIGH_N = 2.0
#: Fewest samples of the onset fit.
MIN_ONSET_SAMPLES = 10


class SurfaceOffset(NamedTuple):
    """The tissue's surface at the first contact against the map's.

    Attributes:
        offset_m: surface - map surface at (x_m, y_m), m (> 0: the map is low).
        sigma_m: 1-sigma of offset_m from the fit's residuals, m.
        surface_z_m: the surface height found, m.
        x_m, y_m: where the tip touched (first sample of the fit), m.
        t_s: its time, s.
        samples: samples in the fit.
        bias_N: the pressing-force bias removed (free-space median), N.
    """

    offset_m: float
    sigma_m: float
    surface_z_m: float
    x_m: float
    y_m: float
    t_s: float
    samples: int
    bias_N: float

    def as_dict(self) -> dict:
        return dict(self._asdict())


def first_contact_offset(
    df: pd.DataFrame, phantom, *, high_N: float = ONSET_HIGH_N
) -> SurfaceOffset | None:
    """The surface at a log's first contact from its approach; None without one.

    Needs :data:`MIN_FREE_S` of record out of contact before the first
    contact (the bias and noise are read there), then fits
    ``(F - bias)^(1/beta)`` linearly on the tip height from where the force
    stands out of the noise (:data:`ONSET_NOISE_Z`, :data:`ONSET_LOW_N`) to
    where it first reaches ``high_N`` above the bias; the zero of the line is
    the surface. The pose and the force are taken as logged (the 9-column
    logs' force is already matched to its pose; the 31-column logs show no
    lag between them: docs/decisions.md, "Force-loop gain of the VS logs").

    Args:
        df: canonical scan frame (t_s, x_m, y_m, z_m, force_sensor_z_N).
        phantom: the map (surface_z, beta).
        high_N: end of the fit above the bias, N (> ONSET_LOW_N).

    Returns:
        :class:`SurfaceOffset`, or None when the log starts in contact, never
        touches, or its onset is too short or does not descend.
    """
    require_columns(df, "t_s", "x_m", "y_m", "z_m", "force_sensor_z_N")
    if not (np.isfinite(high_N) and high_N > ONSET_LOW_N):
        raise VicDrakeError(
            f"high_N must be a number of N above {ONSET_LOW_N}; got {high_N!r}"
        )
    t = df["t_s"].to_numpy(float)
    z = df["z_m"].to_numpy(float)
    f = pressing_force_N(df)
    over = np.flatnonzero(f > CONTACT_THRESHOLD_N)
    if over.size == 0:
        return None
    free = t < t[over[0]] - FREE_MARGIN_S
    if not free.any() or t[free][-1] - t[0] < MIN_FREE_S:
        return None
    bias = float(np.median(f[free]))
    noise = float(np.std(np.diff(f[free])) / np.sqrt(2.0)) if free.sum() > 2 else 0.0
    low = max(ONSET_LOW_N, ONSET_NOISE_Z * noise)
    rel = f - bias
    start = int(np.flatnonzero(free)[-1]) + 1
    above_low = np.flatnonzero(rel[start:] > low)
    if above_low.size == 0:
        return None
    i0 = start + int(above_low[0])
    above_high = np.flatnonzero(rel[i0:] > high_N)
    if above_high.size == 0:
        return None
    i1 = i0 + int(above_high[0])
    if i1 - i0 < MIN_ONSET_SAMPLES:
        return None
    u = np.maximum(rel[i0:i1], 0.0) ** (1.0 / phantom.beta)
    zz = z[i0:i1]
    if not np.all(np.isfinite(u)) or not np.all(np.isfinite(zz)):
        return None
    (slope, icpt), cov = np.polyfit(zz, u, 1, cov=True)
    if not slope < 0:  # the force must grow as the tip descends
        return None
    surface = -icpt / slope
    # Delta method: d s / d icpt = -1 / slope, d s / d slope = icpt / slope^2.
    grad = np.array([icpt / slope**2, -1.0 / slope])
    sigma = float(np.sqrt(max(grad @ cov @ grad, 0.0)))
    x0, y0 = float(df["x_m"].iloc[i0]), float(df["y_m"].iloc[i0])
    map_z = float(np.asarray(phantom.surface_z(x0, y0), float))
    return SurfaceOffset(
        offset_m=float(surface - map_z),
        sigma_m=sigma,
        surface_z_m=float(surface),
        x_m=x0,
        y_m=y0,
        t_s=float(t[i0]),
        samples=int(i1 - i0),
        bias_N=bias,
    )


def controller_map_offset(df: pd.DataFrame, phantom) -> float | None:
    """Median of the real controller's surface minus the map's, m; None without one.

    The controller's surface is the canonical ``surface_z_m`` of a 31-column
    log (tip height plus its logged penetration); a 9-column log or a
    simulated frame without it gives None.
    """
    require_columns(df, "x_m", "y_m", "surface_z_m")
    s = df["surface_z_m"].to_numpy(float)
    ok = np.isfinite(s)
    if not ok.any():
        return None
    x, y = df["x_m"].to_numpy(float)[ok], df["y_m"].to_numpy(float)[ok]
    return float(np.median(s[ok] - np.asarray(phantom.surface_z(x, y), float)))


__all__ = [
    "FREE_MARGIN_S",
    "MIN_FREE_S",
    "MIN_ONSET_SAMPLES",
    "ONSET_HIGH_N",
    "ONSET_LOW_N",
    "ONSET_NOISE_Z",
    "SurfaceOffset",
    "controller_map_offset",
    "first_contact_offset",
]
