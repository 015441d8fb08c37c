"""The force sensor's watchdog: a stuck channel or a dead sensor, and the retract.

A live force/torque sensor never repeats a channel's exact value for long:
its noise moves the last digits every sample. In the rig's twelve logs the
longest run of identical force samples is 6 (10 ms at 500 Hz), and in the two
logs with all three channels no channel ever repeats while another changes:
the repeats are whole samples (the logger read the same sample twice). A
channel that keeps one value while the other channels of the same
reading change is stuck: a frozen converter or a broken wire, and the force
loop on it presses on without feeling the tissue. The fault campaigns draw
such a channel in about one run in seven, and every force above 15 N in
them came from one (docs/decisions.md, "The sensor watchdog").

A sensor whose whole reading stops changing, or that delivers no finite
reading, is dead (a driver that hangs and repeats its last message, a cable
pulled out): the force loop is then blind on every axis at once.

:func:`watch_reading` counts two runs:

- for each channel, the ticks in which it kept its value while another
  channel changed ("live" ticks). A channel trips the watchdog after
  ``stuck_window_s`` of live ticks. Ticks in which nothing changed neither
  count nor reset this run; a non-finite reading is skipped;
- the ticks since the reading last changed (a whole reading repeated, or
  not finite). ``dead_window_s`` of them trip the watchdog as a dead
  sensor (:data:`DEAD_SENSOR`): 0.1 s, 50 samples, ten times the rig's
  longest repeat. The controller rides through a shorter blackout, such as
  one of the fault campaigns' 0.05 s dropouts; two of them back to back
  are a dead sensor.

Once tripped the watchdog latches, and the compliance stage stops using the
sensor: :func:`retract_target` moves the target up from the probe's position
at the trip at ``retract_speed_m_per_s`` to ``retract_height_m`` above it,
tracked with ``retract_stiffness_N_per_m`` and no force term, and holds
there. The scan is over; the operator restarts it on a working sensor.

(No ``from __future__ import annotations`` here: :class:`SensorWatchdogParams`
is loaded by ``yaml_load_typed``, which reads the field types at run time.)
"""

import math
from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError

#: Layout of the watchdog's state vector (``WATCHDOG_SIZE`` numbers).
LAST = slice(0, 3)  # The last finite reading, N.
LIVE_RUN = slice(3, 6)  # Per channel: live ticks it has kept its value.
TRIPPED = 6  # 1 once tripped (latched), else 0.
TRIP_TIME = 7  # When it tripped, s (NaN before).
TRIP_POSITION = slice(8, 11)  # The probe tip at the trip, W, m (NaN before).
STUCK_CHANNEL = 11  # What tripped it: a channel 0, 1, 2, or DEAD_SENSOR; -1 before.
FROZEN_RUN = 12  # Ticks since the reading last changed (repeated or not finite).
WATCHDOG_SIZE = 13
#: The "channel" of a trip by a dead sensor (every channel frozen).
DEAD_SENSOR = 3
#: What tripped the watchdog, by its STUCK_CHANNEL value (0 .. 3).
TRIP_CAUSES = ("x", "y", "z", "all")
_RUN0 = LIVE_RUN.start  # The x channel's live run (y, z follow).
#: Names of the state's elements, in order (for logs and tests).
WATCHDOG_FIELDS = (
    "last_x",
    "last_y",
    "last_z",
    "live_run_x",
    "live_run_y",
    "live_run_z",
    "tripped",
    "trip_time",
    "trip_x",
    "trip_y",
    "trip_z",
    "stuck_channel",
    "frozen_run",
)


@dataclass
class SensorWatchdogParams:
    """Settings of the force sensor's watchdog (see the module docstring)."""

    # Watch the sensor and retract on a stuck channel.
    enabled: bool = True
    # Live time a channel may keep one value before it counts as stuck, s
    # (the rig's longest run of repeated samples spans 0.010 s).
    stuck_window_s: float = 0.05
    # Time without a new reading (every channel repeated, or not finite)
    # after which the sensor counts as dead, s (the rig's longest repeat of
    # a whole reading spans 0.010 s).
    dead_window_s: float = 0.1
    # Speed of the retract, m/s (above the 0.015 m/s a 15 mm breath at
    # 0.33 Hz lifts the chest at).
    retract_speed_m_per_s: float = 0.03
    # How far the retract lifts the target above the probe at the trip, m.
    retract_height_m: float = 0.03
    # Stiffness that tracks the retract target, N/m, each axis.
    retract_stiffness_N_per_m: float = 1000.0

    def __post_init__(self):
        self.validate()

    def validate(self) -> "SensorWatchdogParams":
        """Checks every field; raises VicDrakeError naming the bad one. Returns self."""
        o = "SensorWatchdogParams"
        if not isinstance(self.enabled, bool):
            raise VicDrakeError(
                f"{o}.enabled must be true or false; got {self.enabled!r}"
            )
        for name in (
            "stuck_window_s",
            "dead_window_s",
            "retract_speed_m_per_s",
            "retract_height_m",
            "retract_stiffness_N_per_m",
        ):
            value = getattr(self, name)
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, float))
                or not math.isfinite(value)
                or value <= 0
            ):
                raise VicDrakeError(
                    f"{o}.{name} must be a finite number > 0; got {value!r}"
                )
        return self

    def window_ticks(self, period_s: float) -> int:
        """The stuck window in controller ticks (at least 2)."""
        return _ticks(self.stuck_window_s, period_s)

    def dead_ticks(self, period_s: float) -> int:
        """The dead window in controller ticks (at least 2)."""
        return _ticks(self.dead_window_s, period_s)


def _ticks(window_s: float, period_s: float) -> int:
    """``window_s`` in ticks of ``period_s``, rounded up, at least 2."""
    return max(2, int(math.ceil(window_s / period_s - 1e-9)))


def initial_watchdog_state() -> np.ndarray:
    """The state of a watchdog that has seen nothing."""
    x = np.zeros(WATCHDOG_SIZE)
    x[LAST] = np.nan
    x[TRIP_TIME] = np.nan
    x[TRIP_POSITION] = np.nan
    x[STUCK_CHANNEL] = -1.0
    return x


def watch_reading(
    state: np.ndarray, reading, window_ticks: int, dead_ticks: int
) -> int:
    """Advances the watchdog by one reading, in place.

    Args:
        state: the watchdog's state (:data:`WATCHDOG_SIZE`), updated in place.
            A tripped state is left as it is.
        reading: (3,) the force reading of this tick, N.
        window_ticks: live ticks after which a kept value is stuck.
        dead_ticks: ticks without a new reading after which the sensor is
            dead.

    Returns:
        What trips the watchdog at this reading: the stuck channel (0, 1,
        2) or :data:`DEAD_SENSOR`; -1 when nothing does (or it tripped
        before). The caller records the trip's time and position
        (:func:`record_trip`).
    """
    if state[TRIPPED] >= 0.5:
        return -1
    f0, f1, f2 = float(reading[0]), float(reading[1]), float(reading[2])
    if not (math.isfinite(f0) and math.isfinite(f1) and math.isfinite(f2)):
        return _frozen(state, dead_ticks)
    # Element by element: a slice costs a view per call on this per-tick path.
    l0, l1, l2 = state[0], state[1], state[2]  # LAST
    state[0], state[1], state[2] = f0, f1, f2
    if math.isnan(l0) or math.isnan(l1) or math.isnan(l2):
        return _frozen(state, dead_ticks)  # Nothing to compare with yet.
    same = (f0 == l0, f1 == l1, f2 == l2)
    if all(same):
        # A repeated sample: no evidence on a channel, one more tick dead.
        return _frozen(state, dead_ticks)
    state[FROZEN_RUN] = 0.0
    tripped = -1
    for c in range(3):
        if same[c]:
            state[_RUN0 + c] += 1.0
            if tripped < 0 and state[_RUN0 + c] >= window_ticks:
                tripped = c
        else:
            state[_RUN0 + c] = 0.0
    return tripped


def _frozen(state: np.ndarray, dead_ticks: int) -> int:
    """One more tick without a new reading: :data:`DEAD_SENSOR` at the window."""
    state[FROZEN_RUN] += 1.0
    return DEAD_SENSOR if state[FROZEN_RUN] >= dead_ticks else -1


def record_trip(state: np.ndarray, channel: int, t_s: float, tip_W) -> None:
    """Latches the trip by ``channel`` (0, 1, 2 or :data:`DEAD_SENSOR`) at
    ``t_s`` with the probe tip at ``tip_W``."""
    state[TRIPPED] = 1.0
    state[TRIP_TIME] = float(t_s)
    state[TRIP_POSITION] = np.asarray(tip_W, float).reshape(3)
    state[STUCK_CHANNEL] = float(channel)


def retract_target(
    state: np.ndarray, t_s: float, params: SensorWatchdogParams
) -> np.ndarray:
    """The target position of a tripped watchdog at ``t_s``, W, m.

    The probe's position at the trip, raised at the retract speed up to the
    retract height, then held.
    """
    lift = min(
        params.retract_speed_m_per_s * max(0.0, t_s - state[TRIP_TIME]),
        params.retract_height_m,
    )
    target = np.array(state[TRIP_POSITION], float)
    target[2] += lift
    return target


__all__ = [
    "DEAD_SENSOR",
    "FROZEN_RUN",
    "STUCK_CHANNEL",
    "SensorWatchdogParams",
    "TRIP_CAUSES",
    "TRIP_TIME",
    "WATCHDOG_FIELDS",
    "WATCHDOG_SIZE",
    "initial_watchdog_state",
    "record_trip",
    "retract_target",
    "watch_reading",
]
