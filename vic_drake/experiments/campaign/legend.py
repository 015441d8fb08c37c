"""What each column of a campaign's tables means, in words.

One place for the meanings that summary.html's legends and the console's
lines under its table give: the force on the patient (the tissue's force,
not the sensor's reading), the force limit with its value, the runs that
never touched the patient, the energy tank that CS and CF do not have.
"""

from __future__ import annotations

from vic_drake.paper import CONTACT_THRESHOLD_N


def exceed_label(force_limit_N: float) -> str:
    """The exceedance column's name, with the limit: "P(peak F > 15 N)"."""
    return f"P(peak F > {force_limit_N:g} N)"


def controller_legend(force_limit_N: float) -> list[tuple[str, str]]:
    """(column, meaning) of each column of the per-controller table."""
    limit, contact = f"{force_limit_N:g} N", f"{CONTACT_THRESHOLD_N:g} N"
    return [
        (
            "runs",
            "the controller's runs, failed ones included (a run that failed "
            "with an error has no figures and is in no statistic).",
        ),
        (
            "never touched the patient",
            "runs whose force on the patient never rose above the contact "
            f"threshold, {contact} (e.g. the sensor's watchdog stopped the scan "
            "before the probe reached the patient). Their peak says nothing "
            "about contact forces: they are left out of peak F p50 and kept in "
            f"{exceed_label(force_limit_N)}, as runs that stayed below the limit.",
        ),
        (
            "peak F",
            "a run's highest force of the tissue on the probe, that is on the "
            "patient (the simulated tissue's force, not the force sensor's "
            "reading, which the faults corrupt), N; p50: the median over the "
            "runs that touched the patient; max: the highest over all runs.",
        ),
        (
            exceed_label(force_limit_N),
            "the share of the runs (those failed with an error excepted) whose "
            f"peak force exceeded the force limit, {limit}.",
        ),
        (
            "95 % interval (Wilson)",
            "the Wilson score interval of that share; with few runs it is wide "
            "even when no run exceeded the limit.",
        ),
        (
            "contact loss p50 (s)",
            "the median over the runs of the time the probe lost contact in the "
            "scan proper (not the approach, the final lift or after a watchdog "
            "stop).",
        ),
        (
            "tank min (J)",
            "the lowest energy of the controller's energy tank: the minimum over "
            "the runs, each up to its watchdog stop.",
        ),
        (
            "stopped by the sensor watchdog",
            "runs whose force sensor the watchdog found stuck or dead; it "
            "stopped the scan and the probe retracted.",
        ),
        (
            "—",
            "no value: CS and CF have no energy tank (tank min), or no run gave one.",
        ),
    ]


def worst_runs_legend() -> list[tuple[str, str]]:
    """(column, meaning) of the worst runs' columns not in the table above."""
    return [
        (
            "watchdog stop",
            "when the force sensor's watchdog stopped the run, and why: x, y or "
            "z, that channel stuck; all, the sensor dead; —, it did not stop it.",
        ),
        (
            "failed QP solves / skipped ticks",
            "controller ticks whose stiffness QP failed, and ticks skipped on a "
            "non-finite sensor reading (the stiffness held at its minimum), "
            "each counted up to the watchdog's stop.",
        ),
    ]


def console_legend(force_limit_N: float) -> list[str]:
    """The lines under the console's per-controller table."""
    limit, contact = f"{force_limit_N:g} N", f"{CONTACT_THRESHOLD_N:g} N"
    return [
        "peakF: the tissue's force on the patient (not the sensor's reading), N; "
        "p50 over the runs that touched it",
        f"P(>{limit}): share of the runs whose peakF exceeded the force limit, "
        f"{limit}; no contact: runs never above {contact}, counted as below it",
        "tank min J: '-' for no energy tank (CS, CF); wd stops: runs the force "
        "sensor's watchdog stopped",
    ]


__all__ = [
    "console_legend",
    "controller_legend",
    "exceed_label",
    "worst_runs_legend",
]
