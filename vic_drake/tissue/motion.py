"""Patient motion as a surface offset over time: breathing and traces.

Pure functions of time and plain parameters; the scan diagram adds their sum
to the phantom's lift (:mod:`vic_drake.systems.patient_motion`), and the
breathing's optional lateral part to the phantom's x, y.

Breathing moves the chest along its surface normal. The phantom rides on a
vertical lift joint, and over the scanned top of the chest the surface
normal is within a few degrees of vertical, so the displacement is applied
along W's z axis. One breath is a raised cosine: from exhalation (offset 0)
up to ``amplitude_m`` (peak to peak) and back over one period, so the motion
starts at rest and is continuous from breath to breath. An irregular
breathing draws each breath's period and amplitude around their means.

A breath may also carry a small lateral part (:func:`breathing_lateral_m`):
the same raised cosine, in phase, from 0 to a given (x, y) excursion in W,
each breath's excursion scaled as its depth (its ``depth_scale``).
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError


@dataclass(frozen=True)
class BreathCycles:
    """The breaths of a run: start times (s), periods (s), amplitudes (m).

    ``depth_scale`` is each breath's depth relative to the mean (1 for a
    regular breathing): ``amplitude_m`` is the mean amplitude times it.
    """

    start_s: np.ndarray
    period_s: np.ndarray
    amplitude_m: np.ndarray
    depth_scale: np.ndarray


def breath_cycles(
    *,
    frequency_hz: float,
    amplitude_m: float,
    irregularity: float,
    duration_s: float,
    seed: int,
) -> BreathCycles:
    """The breaths covering [0, duration_s].

    Args:
        frequency_hz: mean breathing rate, Hz (> 0).
        amplitude_m: mean peak-to-peak surface excursion, m (>= 0).
        irregularity: relative standard deviation of each breath's period and
            amplitude (0: regular); draws are clipped to [0.5, 1.5] x the mean.
        duration_s: span to cover, s.
        seed: seed of the irregular draws.
    """
    if not (math.isfinite(frequency_hz) and frequency_hz > 0):
        raise VicDrakeError(f"breathing frequency_hz must be > 0; got {frequency_hz!r}")
    period = 1.0 / frequency_hz
    n = int(math.ceil(max(duration_s, period) / (0.5 * period))) + 1
    rng = np.random.default_rng(seed)
    spread = np.clip(1.0 + irregularity * rng.standard_normal((2, n)), 0.5, 1.5)
    periods = period * (spread[0] if irregularity > 0 else np.ones(n))
    depth = spread[1] if irregularity > 0 else np.ones(n)
    amplitudes = amplitude_m * depth
    starts = np.concatenate([[0.0], np.cumsum(periods)[:-1]])
    return BreathCycles(starts, periods, amplitudes, depth)


def _breath_phase(t: float, cycles: BreathCycles) -> tuple[int, float] | None:
    """(breath index, phase in [0, 1)) at time t; None at rest (t <= 0 or past)."""
    if t <= 0.0:
        return None
    i = int(np.searchsorted(cycles.start_s, t, side="right")) - 1
    i = min(i, cycles.start_s.size - 1)
    phase = (t - cycles.start_s[i]) / cycles.period_s[i]
    if phase >= 1.0:  # Past the last drawn breath: at rest.
        return None
    return i, phase


def breathing_offset_m(t: float, cycles: BreathCycles) -> float:
    """Surface offset at time t, m (raised cosine within each breath)."""
    at = _breath_phase(t, cycles)
    if at is None:
        return 0.0
    i, phase = at
    return float(cycles.amplitude_m[i] * 0.5 * (1.0 - math.cos(2.0 * math.pi * phase)))


def breathing_lateral_m(
    t: float, cycles: BreathCycles, lateral_amplitude_m
) -> tuple[float, float]:
    """Lateral (x, y) offset in W at time t, m: the breath's raised cosine.

    Args:
        t: time, s.
        cycles: the run's breaths.
        lateral_amplitude_m: (x, y) peak-to-peak excursion of a breath of
            mean depth, m (signed: the direction of the excursion); each
            breath's is this times its ``depth_scale``.
    """
    at = _breath_phase(t, cycles)
    if at is None:
        return 0.0, 0.0
    i, phase = at
    shape = float(cycles.depth_scale[i]) * 0.5 * (1.0 - math.cos(2.0 * math.pi * phase))
    return float(lateral_amplitude_m[0]) * shape, float(lateral_amplitude_m[1]) * shape


def load_motion_trace(path: str | os.PathLike) -> np.ndarray:
    """A motion trace from a CSV file with the header ``t_s,z_m``.

    Returns:
        (n, 2) rows [t_s, z_m], times strictly increasing, |z| <= 0.1 m.

    Raises:
        VicDrakeError: the file is missing, has another header, or bad rows.
    """
    if not os.path.isfile(path):
        raise VicDrakeError(f"motion trace {str(path)!r} does not exist")
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or [c.strip() for c in rows[0]] != ["t_s", "z_m"]:
        raise VicDrakeError(
            f"motion trace {str(path)!r} must start with the header 't_s,z_m'"
        )
    try:
        table = np.array([[float(c) for c in row] for row in rows[1:] if row], float)
    except ValueError as exc:
        raise VicDrakeError(f"motion trace {str(path)!r}: {exc}") from None
    if table.ndim != 2 or table.shape[0] < 2 or table.shape[1] != 2:
        raise VicDrakeError(
            f"motion trace {str(path)!r} needs at least 2 rows of two numbers"
        )
    if not np.all(np.isfinite(table)):
        raise VicDrakeError(f"motion trace {str(path)!r} holds non-finite values")
    if np.any(np.diff(table[:, 0]) <= 0):
        raise VicDrakeError(f"motion trace {str(path)!r}: times must increase")
    if np.any(np.abs(table[:, 1]) > 0.1):
        raise VicDrakeError(f"motion trace {str(path)!r}: |z_m| must be <= 0.1 m")
    return table


def trace_offset_m(t: float, table: np.ndarray, scale: float = 1.0) -> float:
    """Offset of a trace at t, m: linear between rows, held outside them."""
    return float(scale * np.interp(t, table[:, 0], table[:, 1]))


__all__ = [
    "BreathCycles",
    "breath_cycles",
    "breathing_lateral_m",
    "breathing_offset_m",
    "load_motion_trace",
    "trace_offset_m",
]
