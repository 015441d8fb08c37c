"""Contact, the scan window and contact loss: one definition of each rule.

Every metric, claim and comparison with a real log decides "in contact",
"the scan proper" and "a contact loss" through the functions here, so a
change of rule changes every number consistently. Why each number is what
it is: docs/decisions.md, "Scan window and contact loss".
"""

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import require_columns
from vic_drake.paper import CONTACT_THRESHOLD_N

#: Shortest contact loss that counts, s (25 ticks at 500 Hz). Dips under the
#: contact threshold in the real logs last at most 12 ms (sensor noise around
#: the threshold); the real losses under a disturbance last 0.3 s and more.
MIN_CONTACT_LOSS_S = 0.05

#: Time skipped after the first contact before the scan window opens, s: the
#: impact transient depends on the approach speed and the sensor's filter,
#: not on the scan behaviour that the metrics are about.
SETTLE_S = 1.0

#: The target counts as "at scan height" within this of its scan height, m.
SCAN_HEIGHT_TOL_M = 1e-3

#: The target is held (not approaching or lifting) while its height changes
#: slower than this, m/s: a tenth of a millimetre a second, against the
#: approaches' 5-15 mm/s; the rig's targets are exactly constant in a scan.
SCAN_HOLD_RATE_M_PER_S = 1e-4


def pressing_force_N(df: pd.DataFrame) -> np.ndarray:
    """Pressing force, N (positive = pushing into the body)."""
    require_columns(df, "force_sensor_z_N")
    return -df["force_sensor_z_N"].to_numpy(dtype=float)


def contact_mask(
    df: pd.DataFrame, threshold_N: float = CONTACT_THRESHOLD_N
) -> np.ndarray:
    """True where the pressing force exceeds the contact threshold."""
    return pressing_force_N(df) > threshold_N


def scan_window(df: pd.DataFrame, *, settle_s: float = SETTLE_S) -> np.ndarray:
    """Samples of the scan proper, as a boolean mask.

    The scan is where the target is held at its scan height: within
    SCAN_HEIGHT_TOL_M of the median target height of the samples in contact
    whose target is held (changing slower than SCAN_HOLD_RATE_M_PER_S: not
    the approach, which a short run may spend most of its contact in), from
    the first contact + ``settle_s`` until the target last leaves that
    height (the final lift). Contact losses inside the scan stay in the
    window: they are what a disturbance does to the scan. The approach and
    the final lift are out, whether or not the probe still touches then
    (CF cannot lift off, so "until the last contact" would score its
    retract as scanning).

    Returns an all-False mask when the probe never touched, or when its
    target was never held while in contact (a run that ends in its approach).
    """
    require_columns(df, "t_s", "z_d_m", "force_sensor_z_N")
    t = df["t_s"].to_numpy(float)
    z_d = df["z_d_m"].to_numpy(float)
    contact = contact_mask(df)
    if len(df) < 2 or not contact.any():
        return np.zeros(len(df), bool)
    t_contact = t[np.argmax(contact)]
    with np.errstate(invalid="ignore", divide="ignore"):
        held = np.abs(np.gradient(z_d, t)) < SCAN_HOLD_RATE_M_PER_S
    if not np.any(contact & held):  # Still approaching: no scan yet.
        return np.zeros(len(df), bool)
    z_scan = np.median(z_d[contact & held])
    at_height = np.abs(z_d - z_scan) < SCAN_HEIGHT_TOL_M
    if not at_height.any():
        return np.zeros(len(df), bool)
    last = np.flatnonzero(at_height)[-1]
    window = at_height & (t >= t_contact + settle_s)
    window[last + 1 :] = False
    return window


def contact_loss_intervals(
    df: pd.DataFrame,
    *,
    window: np.ndarray | None = None,
    min_duration_s: float = MIN_CONTACT_LOSS_S,
) -> list[tuple[float, float]]:
    """Intervals (t_start, t_end) without contact, s.

    A loss lies between the first and the last contact of the run (the free
    motion before the first touch and after the final lift-off are not
    losses) and lasts at least ``min_duration_s``. With ``window`` (a
    boolean mask, e.g. :func:`scan_window`), losses are clipped to the span
    from its first to its last sample; a loss still open at the end of that
    span ends there.
    """
    t = df["t_s"].to_numpy(float)
    contact = contact_mask(df)
    if not contact.any():
        return []
    i0 = int(np.argmax(contact))
    i1 = len(contact) - 1 - int(np.argmax(contact[::-1]))
    if window is not None:
        window = np.asarray(window, bool)
        if not window.any():
            return []
        i0 = max(i0, int(np.argmax(window)))
        i1 = min(i1, len(window) - 1 - int(np.argmax(window[::-1])))
    intervals = []
    start = None
    for i in range(i0, i1 + 1):
        if not contact[i] and start is None:
            start = i
        elif contact[i] and start is not None:
            if t[i] - t[start] >= min_duration_s:
                intervals.append((float(t[start]), float(t[i])))
            start = None
    if start is not None and window is not None and t[i1] - t[start] >= min_duration_s:
        intervals.append((float(t[start]), float(t[i1])))
    return intervals


__all__ = [
    "CONTACT_THRESHOLD_N",
    "MIN_CONTACT_LOSS_S",
    "SCAN_HEIGHT_TOL_M",
    "SETTLE_S",
    "contact_loss_intervals",
    "contact_mask",
    "pressing_force_N",
    "scan_window",
]
