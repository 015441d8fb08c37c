"""The real tip's lateral path replayed in simulation (compare-real's lateral passes).

The simulated tip follows its target through the lateral compliance and the
tissue's friction; the real tip was also pushed sideways by what the
simulation does not hold (a phantom moved by hand, tilted). A lateral pass
runs the scan again with its target moved by the lateral error of the
previous run (real tip minus simulated tip, smoothed, at the same time), so
the simulated tip crosses the map where the real one did. Only the logged
x, y of the tip are used, never its force. Why: docs/decisions.md, "CS_dist:
where the force error comes from".
"""

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import require_columns
from vic_drake.errors import VicDrakeError

#: Period of the corrected target's waypoints, s (the logged target's, see
#: real_logs.WAYPOINT_PERIOD_S).
LATERAL_PERIOD_S = 0.02
#: Width of the centred moving average applied to the lateral error, s: the
#: estimated phantom motion is smoothed over the same 0.2 s.
LATERAL_SMOOTH_S = 0.2
#: Most lateral passes compare-real accepts (each one is a full simulation).
MAX_LATERAL_PASSES = 3
#: compare-real's default: one pass when the phantom's motion is replayed
#: (it was measured under the real tip, so the simulated tip must be there
#: for the replayed surface to be the one under it), none otherwise.
AUTO = "auto"
#: Passes "auto" runs on a replayed log.
AUTO_PASSES_REPLAYED = 1


def check_lateral_passes(value) -> int | str:
    """The number of lateral passes, checked: an int from 0 to
    MAX_LATERAL_PASSES, or :data:`AUTO`."""
    if isinstance(value, str) and value == AUTO:
        return AUTO
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise VicDrakeError(
            f"lateral_passes must be an integer from 0 to {MAX_LATERAL_PASSES} "
            f"or {AUTO!r}; got {value!r}"
        )
    if not 0 <= int(value) <= MAX_LATERAL_PASSES:
        raise VicDrakeError(
            f"lateral_passes must be from 0 to {MAX_LATERAL_PASSES}; got {value!r}"
        )
    return int(value)


def resolve_lateral_passes(value, *, replayed: bool) -> int:
    """The passes to run: ``value`` checked, :data:`AUTO` giving
    :data:`AUTO_PASSES_REPLAYED` when the phantom's motion is replayed, else 0."""
    value = check_lateral_passes(value)
    if value == AUTO:
        return AUTO_PASSES_REPLAYED if replayed else 0
    return value


def _smoothed(v: np.ndarray, n: int) -> np.ndarray:
    if n <= 1:
        return v
    pad = (n // 2, n - 1 - n // 2)
    return np.convolve(np.pad(v, pad, mode="edge"), np.ones(n) / n, "valid")


def lateral_error_m(sim: pd.DataFrame, real: pd.DataFrame, t_s: np.ndarray):
    """(x, y) of the real tip minus the simulated tip at times ``t_s``, m.

    Both records are read on their own clock (the scenario follows the log's);
    outside a record the nearest end is held.
    """
    require_columns(sim, "t_s", "x_m", "y_m")
    require_columns(real, "t_s", "x_m", "y_m")
    out = []
    for c in ("x_m", "y_m"):
        r = np.interp(t_s, real["t_s"].to_numpy(float), real[c].to_numpy(float))
        s = np.interp(t_s, sim["t_s"].to_numpy(float), sim[c].to_numpy(float))
        out.append(r - s)
    return out[0], out[1]


def corrected_waypoints(
    sim: pd.DataFrame,
    real: pd.DataFrame,
    *,
    period_s: float = LATERAL_PERIOD_S,
    smooth_s: float = LATERAL_SMOOTH_S,
) -> list[list[float]]:
    """The target of the next lateral pass as ``[t_s, x_m, y_m, z_m]`` rows.

    The simulated run's own target (``x_d_m``, ``y_d_m``, ``z_d_m`` of
    ``sim``) every ``period_s``, its x and y moved by the real-minus-simulated
    tip position (:func:`lateral_error_m`) averaged over ``smooth_s``; z
    unchanged.

    Raises:
        VicDrakeError: missing columns, non-finite tip positions or bad
            period/smoothing.
    """
    require_columns(sim, "t_s", "x_m", "y_m", "x_d_m", "y_d_m", "z_d_m")
    for name, value in (("period_s", period_s), ("smooth_s", smooth_s)):
        if not (np.isfinite(value) and value > 0):
            raise VicDrakeError(f"{name} must be a positive number of s; got {value!r}")
    for frame, label in ((sim, "simulated"), (real, "real")):
        require_columns(frame, "x_m", "y_m")
        if not np.all(np.isfinite(frame[["x_m", "y_m"]].to_numpy(float))):
            raise VicDrakeError(
                f"the {label} tip's x_m / y_m hold non-finite values; cannot "
                "correct the lateral target"
            )
    t = sim["t_s"].to_numpy(float)
    grid = np.arange(t[0], t[-1] + 1e-9, period_s)
    dx, dy = lateral_error_m(sim, real, grid)
    n = max(1, int(round(smooth_s / period_s)) | 1)
    rows = [
        grid,
        np.interp(grid, t, sim["x_d_m"].to_numpy(float)) + _smoothed(dx, n),
        np.interp(grid, t, sim["y_d_m"].to_numpy(float)) + _smoothed(dy, n),
        np.interp(grid, t, sim["z_d_m"].to_numpy(float)),
    ]
    return np.column_stack(rows).tolist()


def lateral_rms_mm(sim: pd.DataFrame, real: pd.DataFrame, window: np.ndarray) -> float:
    """RMS horizontal distance between the real and simulated tips, mm, over the
    real samples in ``window`` (a mask on ``real``) that the simulation reached
    (NaN when none)."""
    t_all = real["t_s"].to_numpy(float)
    sim_t = sim["t_s"].to_numpy(float)
    keep = np.asarray(window, bool) & (t_all >= sim_t[0]) & (t_all <= sim_t[-1])
    t = t_all[keep]
    if t.size == 0:
        return float("nan")
    dx, dy = lateral_error_m(sim, real[keep], t)
    return float(1e3 * np.sqrt(np.mean(dx**2 + dy**2)))


__all__ = [
    "LATERAL_PERIOD_S",
    "LATERAL_SMOOTH_S",
    "MAX_LATERAL_PASSES",
    "check_lateral_passes",
    "corrected_waypoints",
    "lateral_error_m",
    "lateral_rms_mm",
]
