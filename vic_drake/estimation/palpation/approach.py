"""Where a sinusoidal palpation starts: the end of the approach.

A palpation log begins with the approach: from the first touch the probe
sinks into the tissue until it oscillates about its operating depth. Those
first cycles are a loading ramp, not the palpation (the paper's load tests
show that the first loading is where the models differ most), and they are
in the log's first seconds, exactly where the shortest windows of Fig. 3
sit. :func:`palpation_start` finds the palpation's period from the signal
and the first cycle after which the mean depth has stopped moving.
"""

from dataclasses import dataclass

import numpy as np
from scipy.signal import periodogram

from vic_drake.errors import VicDrakeError

DEFAULT_SETTLE_FRACTION = 0.1
"""The approach is over at the first cycle whose mean depth differs from the
next cycle's by at most this fraction of the next cycle's peak-to-peak depth
(the ramp per cycle is small against the palpation's stroke)."""

MIN_PALPATION_HZ = 0.2
"""Lowest palpation frequency looked for, Hz (slower content is the approach
and depth changes, not the palpation)."""

MIN_CYCLES = 4
"""Fewest whole cycles in contact for a period to be used."""


@dataclass(frozen=True)
class PalpationStart:
    """The end of a palpation log's approach.

    Attributes:
        period_s: the palpation's period, s; None when the log shows no
            oscillation of at least :data:`MIN_CYCLES` cycles (then nothing
            is skipped).
        start_s: seconds after the first in-contact sample at which the
            palpation starts (a whole number of periods; 0 when nothing is
            skipped).
        cycles_skipped: whole cycles of approach skipped.
    """

    period_s: float | None
    start_s: float
    cycles_skipped: int


def palpation_period_s(t_s, signal) -> float | None:
    """The dominant period of ``signal`` sampled at ``t_s``, or None.

    Periodogram of the linearly detrended signal resampled on a uniform grid,
    searched from :data:`MIN_PALPATION_HZ` to a quarter of the sample rate;
    None if fewer than :data:`MIN_CYCLES` periods fit in the span or the
    signal is constant.
    """
    t = np.asarray(t_s, float)
    x = np.asarray(signal, float)
    ok = np.isfinite(t) & np.isfinite(x)
    t, x = t[ok], x[ok]
    if t.size < 16 or np.ptp(x) == 0.0:
        return None
    dt = float(np.median(np.diff(t)))
    if not dt > 0.0:
        return None
    grid = np.arange(t[0], t[-1], dt)
    freq, power = periodogram(np.interp(grid, t, x), fs=1.0 / dt, detrend="linear")
    band = (freq >= MIN_PALPATION_HZ) & (freq <= 0.25 / dt)
    if not band.any() or not np.any(power[band] > 0.0):
        return None
    f = float(freq[band][np.argmax(power[band])])
    if f * (t[-1] - t[0]) < MIN_CYCLES:
        return None
    return 1.0 / f


def palpation_start(
    t_s,
    penetration_m,
    in_contact,
    *,
    z_target_m=None,
    settle_fraction: float = DEFAULT_SETTLE_FRACTION,
) -> PalpationStart:
    """The first whole cycle after the approach.

    The period comes from the commanded height when it is given (the rig's
    target is the sinusoid itself), else from the in-contact penetration.
    Cycles are counted from the first in-contact sample; cycle k is settled
    when its mean penetration is within ``settle_fraction`` of cycle k + 1's
    peak-to-peak penetration of cycle k + 1's mean. Only the first half of
    the log is searched: a log that never settles there keeps its start.

    Args:
        t_s, penetration_m: (n,) time and penetration.
        in_contact: (n,) bool, the samples the fits use.
        z_target_m: (n,) commanded height, or None.
        settle_fraction: see :data:`DEFAULT_SETTLE_FRACTION`; in (0, 1].
    """
    if not (np.isfinite(settle_fraction) and 0.0 < settle_fraction <= 1.0):
        raise VicDrakeError(
            f"settle_fraction must be in (0, 1]; got {settle_fraction!r}"
        )
    t = np.asarray(t_s, float)
    eps = np.asarray(penetration_m, float)
    mask = np.asarray(in_contact, bool)
    if not mask.any():
        raise VicDrakeError("palpation_start: no sample is in contact")
    first = int(np.argmax(mask))
    t0, t_end = float(t[first]), float(t[mask][-1])
    period = None
    if z_target_m is not None:
        period = palpation_period_s(t[first:], np.asarray(z_target_m, float)[first:])
    if period is None:
        period = palpation_period_s(t[mask], eps[mask])
    if period is None:
        return PalpationStart(None, 0.0, 0)
    n_cycles = int(np.floor((t_end - t0) / period + 1e-9))
    cycle = np.floor((t - t0) / period + 1e-9).astype(int)
    stats = []
    for k in range(n_cycles // 2 + 1):
        sel = mask & (cycle == k)
        if sel.sum() < 4:
            return PalpationStart(period, 0.0, 0)
        stats.append((float(np.mean(eps[sel])), float(np.ptp(eps[sel]))))
    for k in range(len(stats) - 1):
        (mean_k, _), (mean_next, ptp_next) = stats[k], stats[k + 1]
        if abs(mean_next - mean_k) <= settle_fraction * ptp_next:
            return PalpationStart(period, k * period, k)
    return PalpationStart(period, 0.0, 0)
