"""Faults of the force sensor as the controller reads it (pure functions).

A faulty reading of the true sensor force ``u_k`` at control tick k:

1. extra latency: the reading delivered at tick k is ``u_{k - L}``;
2. bias and noise: ``+ bias + n_k`` with n_k ~ N(0, sigma^2) per axis;
3. spikes: at random ticks (Poisson, ``spike_rate_per_s``) a single-tick
   jump of ``spike_magnitude_N`` in a random direction;
4. a stuck channel: from ``stuck_start_s`` on, one axis keeps the value it
   had then;
5. dropouts: during random windows (Poisson starts, ``dropout_duration_s``
   long) the reading is the last delivered value (``hold``) or NaN (``nan``);
6. a dead sensor: from ``dead_start_s`` on, a dropout that never ends.

The random parts are drawn once per run from its seed
(:func:`fault_schedule`), so a run is exactly repeatable on any worker.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError

#: What a dropout delivers.
DROPOUT_MODES = ("hold", "nan")


@dataclass(frozen=True)
class FaultSchedule:
    """The random part of a run's faults, one row per control tick.

    Attributes:
        noise_N: (n, 3) additive noise.
        spikes_N: (n, 3) single-tick spikes (zero rows between spikes).
        dropout: (n,) True where the reading drops out.
    """

    noise_N: np.ndarray
    spikes_N: np.ndarray
    dropout: np.ndarray

    @property
    def ticks(self) -> int:
        return int(self.dropout.size)


def fault_schedule(
    *,
    ticks: int,
    period_s: float,
    seed: int,
    noise_std_N: float = 0.0,
    spike_rate_per_s: float = 0.0,
    spike_magnitude_N: float = 0.0,
    dropout_rate_per_s: float = 0.0,
    dropout_duration_s: float = 0.0,
) -> FaultSchedule:
    """Draws the noise, spikes and dropout windows of ``ticks`` control ticks."""
    if ticks < 1 or not period_s > 0:
        raise VicDrakeError(
            f"fault_schedule needs ticks >= 1 and period_s > 0; got {ticks}, {period_s}"
        )
    rng = np.random.default_rng([int(seed), 0x5E450])
    noise = noise_std_N * rng.standard_normal((ticks, 3)) if noise_std_N > 0 else None
    spikes = np.zeros((ticks, 3))
    if spike_rate_per_s > 0 and spike_magnitude_N > 0:
        hit = rng.random(ticks) < spike_rate_per_s * period_s
        direction = rng.standard_normal((int(hit.sum()), 3))
        direction /= np.linalg.norm(direction, axis=1, keepdims=True)
        spikes[hit] = spike_magnitude_N * direction
    dropout = np.zeros(ticks, bool)
    if dropout_rate_per_s > 0 and dropout_duration_s > 0:
        starts = np.flatnonzero(rng.random(ticks) < dropout_rate_per_s * period_s)
        length = max(1, int(round(dropout_duration_s / period_s)))
        for s in starts:
            dropout[s : s + length] = True
    return FaultSchedule(
        noise_N=np.zeros((ticks, 3)) if noise is None else noise,
        spikes_N=spikes,
        dropout=dropout,
    )


def faulty_reading(
    raw_N: np.ndarray,
    *,
    tick: int,
    t_s: float,
    schedule: FaultSchedule,
    bias_N: np.ndarray,
    stuck_channel: int,
    stuck_start_s: float,
    stuck_value_N: float,
    previous_N: np.ndarray,
    dropout_mode: str,
    dead_start_s: float = math.inf,
) -> np.ndarray:
    """The reading delivered at one tick (steps 2-6 of the module docstring).

    Args:
        raw_N: (3,) the (already delayed) true reading.
        tick: control tick index (wraps around the schedule's length).
        t_s: time of the tick, s.
        schedule: the run's :class:`FaultSchedule`.
        bias_N: (3,) constant bias.
        stuck_channel: -1 (none) or the axis 0..2 that sticks.
        stuck_start_s: when it sticks, s.
        stuck_value_N: the value it sticks at (NaN: this tick's value).
        previous_N: (3,) the reading delivered at the previous tick.
        dropout_mode: "hold" or "nan" (dropouts and a dead sensor).
        dead_start_s: when the sensor dies, s (inf: never).
    """
    k = tick % schedule.ticks
    if schedule.dropout[k] or t_s >= dead_start_s:
        if dropout_mode == "nan":
            return np.full(3, np.nan)
        return np.array(previous_N, float)
    out = np.asarray(raw_N, float) + bias_N + schedule.noise_N[k] + schedule.spikes_N[k]
    if stuck_channel >= 0 and t_s >= stuck_start_s and not math.isnan(stuck_value_N):
        out[stuck_channel] = stuck_value_N
    return out


__all__ = ["DROPOUT_MODES", "FaultSchedule", "fault_schedule", "faulty_reading"]
