"""When a contact ends above the contact threshold: the force's fall back
to the free-air level it rose from.

The sensor's force is the tissue's plus whatever the sensor adds. A bias on
the pressing side stands above the contact threshold in free air, so a
probe that the tissue leaves (a breathing chest that draws away) reads the
bias, and the threshold never ends the contact. The gate follows the force
through a first-order low-pass (``latch_rise_filter_s``, each sample's
step clipped at :data:`MAX_STEP_N`) and keeps:

- the filtered force;
- the level the contact rose from: the filtered force's lowest value since
  the gate was armed (the raw force above ``contact_threshold_N``, or the
  filtered one still above it: a single low sample inside a contact, from
  noise or a spike, does not disarm it);
- the phase: :data:`ONSET` (armed, the force has not yet risen by
  ``contact_threshold_N`` above that level), :data:`RISEN` (it has), or
  :data:`FALLEN` (it had risen and has fallen back to within
  ``contact_fall_margin_N`` of that level; from the fall on, the level is
  tracked anew and the force must rise again);
- the free-air descent: how far below its highest point since the gate
  was armed the tip has been while the filtered force was within
  ``contact_fall_margin_N`` of that level (and that highest point). A
  net descent: the back and forth of a dither or a palpation does not add
  up.

The filter starts from a raw sample (the first, or the first after a gap
longer than ``max_gap_s``), which holds the raw noise and can be a spike.
Until it has settled (:data:`SETTLE_TIME_CONSTANTS` filter time
constants), an armed gate takes no level, counts no descent and sees no
rise or fall: a first sample a few tenths of a newton low would otherwise
stand as a level that the filtered force never comes back to within
``contact_fall_margin_N``, and neither the free-air descent nor the tare
would ever come.

The fall counts only once the free-air descent is at least
``contact_fall_air_travel_m``: the tip went down with nothing answering,
so the level is what the sensor reads in free air. A gate armed inside a
contact (a log that starts pressed in) has a level that is tissue force:
a palpation that returns to the depth it started from has not left the
tissue, and only the threshold ends its contacts. With an unbiased
sensor the level is at most about the threshold, and the fall ends a
contact about where the threshold does.

The gate also keeps the sensor's **tare**: the level, when the free-air
descent has confirmed it as the sensor's free-air reading (at the level,
in :data:`ONSET` or :data:`FALLEN`) and it is above the contact threshold
(a free-air reading that would read as contact: a bias on the pressing
side). The gate's disarming (a reading at or below the threshold) sets
the tare back to 0: the sensor then reads at most the threshold, as an
unbiased one does. So an unbiased sensor, a bias at or below the
threshold, and a log that starts pressed in are not tared; a tissue so
soft that its force stays within ``contact_fall_margin_N`` over
``contact_fall_air_travel_m`` arms the gate at about the threshold,
which a level above the threshold leaves out. The callers subtract the
tare from the force before anything else reads it: the contact test, the
surface latch, the update and the slope fit then see the tissue's force,
not the bias (a bias read as tissue force starts kappa high, and a latch
at the lowest value of a flat biased reading stands millimetres above the
tissue). Taring at the level (the filtered force's lowest value) leaves
that value's noise excursion below the bias's mean in the tared force: a
small part of the filter's noise, well below the threshold.

``latch_rise_filter_s`` 0: the gate is never :data:`FALLEN` and never
tares.

The callers (:func:`~vic_drake.estimation.online.core.prepare` and the
slope fit's :func:`~vic_drake.estimation.online.slope.advance`) keep the
gate's state in their own at an offset; :data:`FALLEN` is out of contact
for both (docs/decisions.md, "A contact ends where its force falls
back" and "The online tare").
"""

from __future__ import annotations

import math

from vic_drake.estimation.online.params import OnlineEstimatorParams

#: Entries of the gate's state: the filtered force, N (NaN before the
#: first sample); the level the contact rose from, N (NaN: not armed);
#: the phase; the free-air descent, m; the tip's highest point since
#: armed, m (NaN: not armed); the tare, N (at :data:`TARE`); the time
#: since the filter (re)started from a raw sample, s.
GATE_SIZE = 7
#: Offset of the tare in the gate's state, N (0 until a free-air level).
TARE = 5
_AGE = 6
#: The filter settles this many ``latch_rise_filter_s`` after it starts
#: from a raw sample (the first, or the first after a gap): e^-3, 5 % of
#: that sample's noise, is left. Until then the level, the descent and
#: the fall wait: one noisy sample would otherwise set a level that the
#: filtered force never comes back to.
SETTLE_TIME_CONSTANTS = 3.0
#: The filter takes at most this step of the force from one sample, N: a
#: spike (tens of N for a sample) would otherwise move the level that a
#: contact rises from, and its decay would read as a rise.
MAX_STEP_N = 2.0
#: Phases. OUT: the force and the filtered force are at or below the
#: threshold (not armed).
OUT, ONSET, RISEN, FALLEN = 0.0, 1.0, 2.0, 3.0
_DISARMED = [math.nan, OUT, 0.0, math.nan, 0.0]  # the gate's state but the force


def gate_initial_state() -> list[float]:
    """A gate before its first sample."""
    return [math.nan, *_DISARMED, 0.0]


def advance_gate(
    g: list[float],
    i: int,
    dt: float,
    z: float,
    force: float,
    p: OnlineEstimatorParams,
) -> float:
    """One good sample of the gate at ``g[i:i + GATE_SIZE]`` (in place).

    Args:
        g, i: the state list and the gate's offset in it.
        dt: time since the previous good sample, s (0 at the first; a gap
            longer than ``p.max_gap_s`` restarts the filter).
        z: the tip's height, m (down = into the tissue).
        force: the sample's force, N (positive: pushing the probe up).
        p: ``latch_rise_filter_s``, ``contact_threshold_N``,
            ``contact_fall_margin_N``, ``contact_fall_air_travel_m``,
            ``max_gap_s``.

    Returns:
        The phase after the sample (the tare after it: ``g[i + TARE]``).
    """
    tau = p.latch_rise_filter_s
    threshold = p.contact_threshold_N
    f = g[i]
    if tau == 0.0 or f != f or not 0.0 < dt <= p.max_gap_s:  # (f != f: NaN)
        f = force
        g[i + _AGE] = 0.0
    else:  # A spike moves the filter as a step of MAX_STEP_N would.
        step = force - f
        step = -MAX_STEP_N if step < -MAX_STEP_N else min(step, MAX_STEP_N)
        f += dt / (tau + dt) * step
        g[i + _AGE] += dt
    g[i] = f
    if force <= threshold and f <= threshold:
        g[i + 1 : i + _AGE] = _DISARMED
        return OUT
    if g[i + _AGE] < SETTLE_TIME_CONSTANTS * tau:  # Armed, not yet settled.
        if g[i + 2] == OUT:
            g[i + 2] = ONSET
        return g[i + 2]
    if not z <= g[i + 4]:  # The highest tip since the gate was armed.
        g[i + 4] = z
    phase = g[i + 2]
    if phase == RISEN:
        if f > g[i + 1] + p.contact_fall_margin_N or tau == 0.0:
            return RISEN
        if g[i + 3] < p.contact_fall_air_travel_m:
            return RISEN
        g[i + 1] = f
        g[i + TARE] = f if f > threshold else 0.0
        g[i + 2] = FALLEN
        return FALLEN
    level = g[i + 1]
    if not f >= level:  # A new low (NaN: the first armed sample).
        g[i + 1] = level = f
    if f <= level + p.contact_fall_margin_N:  # At the level: free air, so far.
        g[i + 3] = max(g[i + 3], g[i + 4] - z)
        if tau != 0.0 and g[i + 3] >= p.contact_fall_air_travel_m:
            # Free air confirmed: the level is the sensor's reading.
            g[i + TARE] = level if level > threshold else 0.0
    if tau == 0.0 or f - level >= threshold:
        phase = RISEN
    elif phase == OUT:
        phase = ONSET
    g[i + 2] = phase
    return phase


__all__ = [
    "FALLEN",
    "GATE_SIZE",
    "MAX_STEP_N",
    "ONSET",
    "OUT",
    "RISEN",
    "SETTLE_TIME_CONSTANTS",
    "TARE",
    "advance_gate",
    "gate_initial_state",
]
