"""Signal conditioning for the offline fits: uniform resampling, sensor-lag
shifts and smoothed derivatives of logged positions.

The real rig logs at about 500 Hz with slightly uneven timestamps (the
UR3e's 2 ms tick, jittered by ROS). Every function here
accepts uneven timestamps: derivatives are computed on a uniform grid at the
median sample period (linear interpolation onto the grid, Savitzky-Golay
there) and interpolated back onto the original timestamps, so callers never
see the grid.

Smoothing: a cubic Savitzky-Golay filter over a window of
:data:`DEFAULT_DERIVATIVE_WINDOW_S` = 0.05 s (25 samples at 500 Hz). It
passes the fastest palpation (2.5 Hz) nearly unchanged while it averages the
tick-level jitter of the logged tip height that makes a raw finite
difference of z-ddot useless (docs/decisions.md, "Derivative window").
"""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

from vic_drake.errors import VicDrakeError

DEFAULT_DERIVATIVE_WINDOW_S = 0.05
"""Savitzky-Golay window for z, z-dot, z-ddot, s (see the module docstring)."""

DEFAULT_POLYORDER = 3


def median_period(t_s) -> float:
    """Median sample period of increasing timestamps, s.

    Raises:
        VicDrakeError: fewer than 2 samples or timestamps not increasing.
    """
    t_s = np.asarray(t_s, dtype=float)
    if t_s.ndim != 1 or t_s.size < 2:
        raise VicDrakeError(f"need at least 2 timestamps; got shape {t_s.shape}")
    dt = np.diff(t_s)
    if not np.all(dt > 0.0):
        bad = int(np.argmax(dt <= 0.0))
        raise VicDrakeError(
            f"timestamps must increase strictly; t[{bad}] = {t_s[bad]!r} >= "
            f"t[{bad + 1}] = {t_s[bad + 1]!r}"
        )
    return float(np.median(dt))


def uniform_grid(t_s, period_s: float | None = None) -> np.ndarray:
    """Uniform timestamps from t_s[0] to at most t_s[-1] at ``period_s``.

    ``period_s`` defaults to the median period of ``t_s``.
    """
    t_s = np.asarray(t_s, dtype=float)
    dt = median_period(t_s) if period_s is None else float(period_s)
    if not dt > 0.0:
        raise VicDrakeError(f"period_s must be > 0; got {period_s!r}")
    n = int(np.floor((t_s[-1] - t_s[0]) / dt + 1e-9)) + 1
    return t_s[0] + dt * np.arange(n)


def resample(t_s, values, t_new_s) -> np.ndarray:
    """Linear interpolation of ``values`` (n,) sampled at ``t_s`` onto ``t_new_s``."""
    return np.interp(np.asarray(t_new_s, float), np.asarray(t_s, float), values)


def shift_signal(t_s, values, lag_s: float) -> np.ndarray:
    """``values`` advanced by ``lag_s``: returns x(t + lag_s) at each ``t_s``.

    Use it to undo a sensor that reports x(t) at t + lag_s. Samples whose
    t + lag_s falls past the last timestamp are NaN (the caller drops them);
    fractional lags are linearly interpolated.
    """
    t_s = np.asarray(t_s, dtype=float)
    t_query = t_s + float(lag_s)
    out = np.interp(t_query, t_s, np.asarray(values, float))
    out[(t_query > t_s[-1]) | (t_query < t_s[0])] = np.nan
    return out


def gap_free_mask(t_s, window_s: float, *, max_gap_factor: float = 4.0) -> np.ndarray:
    """True for samples farther than ``window_s`` from any timestamp gap.

    A gap is a step longer than ``max_gap_factor`` median periods (dropped
    messages). Derivatives bridged across a gap by the uniform resampling are
    unreliable within one filter window of it.
    """
    t_s = np.asarray(t_s, dtype=float)
    dt = np.diff(t_s)
    gaps = np.flatnonzero(dt > max_gap_factor * median_period(t_s))
    ok = np.ones(t_s.shape, bool)
    for i in gaps:
        ok &= (t_s < t_s[i] - window_s) | (t_s > t_s[i + 1] + window_s)
    return ok


def savgol_window_samples(window_s: float, period_s: float, polyorder: int) -> int:
    """Odd window length in samples for a ``window_s`` Savitzky-Golay filter."""
    if not window_s > 0.0:
        raise VicDrakeError(f"derivative window must be > 0 s; got {window_s!r}")
    n = int(round(window_s / period_s))
    n += 1 - n % 2  # Odd.
    return max(n, polyorder + 2 + (polyorder + 2 + 1) % 2)


def smoothed_derivatives(
    t_s,
    x,
    *,
    window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    polyorder: int = DEFAULT_POLYORDER,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Savitzky-Golay smoothed signal and its first two time derivatives.

    Works on uneven timestamps: the signal is linearly resampled onto a
    uniform grid at the median period, filtered there (``mode="interp"``:
    polynomial fits at the ends rather than padding) and interpolated back.

    Args:
        t_s: (n,) increasing timestamps, s.
        x: (n,) signal (e.g. tip height z, m).
        window_s: filter window, s (rounded to an odd number of samples).
        polyorder: polynomial order of the local fits (>= 2).

    Returns:
        (x_smooth, x_dot, x_ddot) at ``t_s``, in units of x, x/s, x/s^2.

    Raises:
        VicDrakeError: too few samples for the window, or bad timestamps.
    """
    t_s = np.asarray(t_s, dtype=float)
    x = np.asarray(x, dtype=float)
    if x.shape != t_s.shape:
        raise VicDrakeError(f"signal shape {x.shape} != timestamp shape {t_s.shape}")
    if polyorder < 2:
        raise VicDrakeError(
            f"polyorder must be >= 2 for a second derivative; got {polyorder}"
        )
    dt = median_period(t_s)
    grid = uniform_grid(t_s, dt)
    window = savgol_window_samples(window_s, dt, polyorder)
    if grid.size < window:
        raise VicDrakeError(
            f"{grid.size} samples are fewer than the {window}-sample "
            f"({window_s} s) derivative window"
        )
    xg = np.interp(grid, t_s, x)
    out = []
    for deriv in (0, 1, 2):
        yg = savgol_filter(xg, window, polyorder, deriv=deriv, delta=dt, mode="interp")
        out.append(np.interp(t_s, grid, yg))
    return out[0], out[1], out[2]
