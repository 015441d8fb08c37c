"""How long a scan may be simulated past its scenario's own run.

The scan commands (``vic-drake scan``, ``vic-drake compare-online``) take a
``--duration``; one far beyond the scenario's trajectory (the probe only
holds still after its end) is refused before any simulation. Kept apart
from the scenario package so the command line can show the limit without
importing it (it imports Drake).
"""

from __future__ import annotations

from vic_drake.errors import VicDrakeError

#: How far past a scenario's full run --duration may reach, s (the probe
#: only holds still after its trajectory's end).
MAX_EXTRA_DURATION_S = 60.0


def check_scan_duration(scenario, duration_s: float) -> None:
    """Refuses a --duration far beyond the scenario's trajectory.

    Raises:
        VicDrakeError: more than :data:`MAX_EXTRA_DURATION_S` past the
            scenario's full run; the message gives the trajectory's length.
    """
    end = float(scenario.trajectory.end_time_s)
    full = max(float(scenario.total_duration_s), end + 1.0)
    limit = full + MAX_EXTRA_DURATION_S
    if duration_s > limit:
        raise VicDrakeError(
            f"--duration {duration_s:g} s is far beyond the scenario: its trajectory "
            f"ends at {end:.1f} s (the default run is {scenario.total_duration_s:.1f} "
            f"s); give at most {limit:.1f} s"
        )


__all__ = ["MAX_EXTRA_DURATION_S", "check_scan_duration"]
