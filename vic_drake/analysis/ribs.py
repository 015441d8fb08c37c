"""The rib detector: ribs as the prominent peaks of a kappa profile.

One rule serves the claim C3 (ribs in the estimated and the measured map)
and the map's comparison with its phantom's truth (are the ribs where the
phantom has them). Why these numbers: docs/decisions.md, "One rib detector".
"""

from dataclasses import dataclass

import numpy as np
from scipy.signal import find_peaks

from vic_drake.errors import VicDrakeError

#: A kappa peak is a rib when its prominence (above the higher of its two
#: neighbouring troughs) is at least this fraction of the map's median kappa:
#: the measured map's weakest rib (under the muscle) has about 9 %, the soft
#: tissue's texture bumps less than 3 %.
RIB_MIN_PROMINENCE = 0.05

#: A rib "stands out" when its prominence is at least this fraction of the
#: map's median kappa (a clearly visible line in a colour map of kappa).
RIB_STRONG_PROMINENCE = 0.15

#: A rib is "less evident" when its prominence is at most this fraction of
#: the median prominence of the ribs that stand out.
RIB_WEAK_FRACTION = 0.5


@dataclass(frozen=True)
class RibPeaks:
    """Ribs found along one axis.

    Attributes:
        position_m: (n,) rib positions along the axis, m, ascending.
        prominence: (n,) prominence of each peak, in kappa's unit.
        reference: the kappa the prominences are relative to (the map's
            median kappa).
    """

    position_m: np.ndarray
    prominence: np.ndarray
    reference: float

    @property
    def relative(self) -> np.ndarray:
        """Prominence / reference kappa."""
        return self.prominence / self.reference


def find_ribs(axis_m, profile, *, reference: float | None = None) -> RibPeaks:
    """Peaks of a kappa profile whose prominence is at least RIB_MIN_PROMINENCE.

    Args:
        axis_m: (n,) positions of the profile's samples, m, ascending.
        profile: (n,) kappa along the axis (e.g. the median across the ribs).
        reference: the kappa prominences are measured against (default: the
            profile's median; pass the whole map's median when the profile
            is a cut of a map).

    Peaks on the first or the last sample cannot be told from an edge and
    are never reported.
    """
    x = np.asarray(axis_m, float)
    p = np.asarray(profile, float)
    if x.ndim != 1 or p.shape != x.shape:
        raise VicDrakeError(
            f"find_ribs: axis_m and profile must be 1-D of the same length; got shapes "
            f"{x.shape} and {p.shape}"
        )
    ref = float(np.median(p)) if reference is None else float(reference)
    if x.size < 3 or not np.isfinite(ref) or ref <= 0:
        return RibPeaks(np.zeros(0), np.zeros(0), ref)
    peaks, props = find_peaks(p, prominence=RIB_MIN_PROMINENCE * ref)
    return RibPeaks(x[peaks], np.asarray(props["prominences"], float), ref)


def rib_prominences(x_m, y_m, kappa, *, across: str = "x") -> dict:
    """The ribs of a kappa map and how evident each is (claim C3).

    The ribs run along y on the phantom (a scan along x crosses them), so the
    profile is the median of kappa over y at each x; prominences are relative
    to the map's median kappa.

    Args:
        x_m: (nx,) grid axis, m.
        y_m: (ny,) grid axis, m.
        kappa: (nx, ny) Hunt-Crossley elasticity.
        across: axis the ribs are crossed along ("x" or "y").

    Returns:
        dict: rib_position_m, prominence (absolute), relative (prominence /
        median kappa), n_ribs, n_strong, n_weak, weakest_to_median_strong,
        min_spacing_m, median_kappa.
    """
    x = np.asarray(x_m, float)
    y = np.asarray(y_m, float)
    k = np.asarray(kappa, float)
    if k.shape != (x.size, y.size):
        raise VicDrakeError(
            f"rib_prominences: kappa has shape {k.shape}; expected (len(x), len(y)) = "
            f"({x.size}, {y.size})"
        )
    if across not in ("x", "y"):
        raise VicDrakeError(
            f"rib_prominences: across must be 'x' or 'y', got {across!r}"
        )
    axis, prof = (
        (x, np.median(k, axis=1)) if across == "x" else (y, np.median(k, axis=0))
    )
    median = float(np.median(k))
    ribs = find_ribs(axis, prof, reference=median)
    prom, rel = ribs.prominence, ribs.relative
    strong = rel >= RIB_STRONG_PROMINENCE
    ref = np.median(prom[strong]) if strong.any() else np.nan
    weak = (
        prom <= RIB_WEAK_FRACTION * ref if strong.any() else np.zeros(prom.size, bool)
    )
    return {
        "rib_position_m": ribs.position_m.tolist(),
        "prominence": prom.tolist(),
        "relative": rel.tolist(),
        "n_ribs": int(prom.size),
        "n_strong": int((strong & ~weak).sum()),
        "n_weak": int(weak.sum()),
        "weakest_to_median_strong": float(prom.min() / ref) if strong.any() else None,
        "min_spacing_m": float(np.min(np.diff(np.sort(ribs.position_m))))
        if prom.size > 1
        else None,
        "median_kappa": median,
    }


__all__ = [
    "RIB_MIN_PROMINENCE",
    "RIB_STRONG_PROMINENCE",
    "RIB_WEAK_FRACTION",
    "RibPeaks",
    "find_ribs",
    "rib_prominences",
]
