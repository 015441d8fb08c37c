"""The real phantom's surface against the published map: the rig's calibration.

:func:`surface_calibration` decides the offset compare-real raises the
simulated tissue by (the controller keeps reading the published map, as the
real one read its own): a number given by the caller; "auto", the log's own
first-contact estimate when the log approaches from free space
(:func:`vic_drake.analysis.surface_offset.first_contact_offset`) and the
estimate is plausible (within +-MAX_SURFACE_OFFSET_M, 1-sigma at most
MAX_FIRST_CONTACT_SIGMA_M), else the
rig's default :data:`vic_drake.realdata.RIG_SURFACE_OFFSET_M` (which
:func:`rig_surface_offset` recomputes from the calibration logs); "none",
no offset. compare-real's default is :data:`DEFAULT_SURFACE_OFFSET`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.surface_offset import (
    controller_map_offset,
    first_contact_offset,
)
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import RIG_SURFACE_OFFSET_M, read_bag

#: Largest offset accepted, m (the scenario's map errors allow +-0.02 m).
MAX_SURFACE_OFFSET_M = 0.02
#: The words compare-real's surface offset takes besides a number.
SURFACE_OFFSET_MODES = ("none", "auto")
#: compare-real's default (docs/decisions.md, "Surface calibration of
#: compare-real").
DEFAULT_SURFACE_OFFSET = "auto"
#: Largest 1-sigma of a first-contact estimate that "auto" uses, m; a
#: looser fit (a noisy or irregular approach) falls back on the rig default.
MAX_FIRST_CONTACT_SIGMA_M = 0.0005
#: Where the offset came from (``surface_offset_source`` of compare-real).
SURFACE_OFFSET_SOURCES = ("none", "given", "first contact", "rig default")


def check_surface_offset(value, name: str = "surface_offset_m") -> float:
    """``value`` as a float if it is a finite offset within +-MAX_SURFACE_OFFSET_M."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise VicDrakeError(f"{name} must be a number of m; got {value!r}") from None
    if not (np.isfinite(v) and abs(v) <= MAX_SURFACE_OFFSET_M):
        raise VicDrakeError(
            f"{name} must be a finite offset within +-{MAX_SURFACE_OFFSET_M} m; "
            f"got {value!r}"
        )
    return v


def parse_surface_offset(value):
    """A surface offset argument checked: one of SURFACE_OFFSET_MODES or a float, m.

    None stands for :data:`DEFAULT_SURFACE_OFFSET`.

    Raises:
        VicDrakeError: another word, or a number outside +-MAX_SURFACE_OFFSET_M.
    """
    if value is None:
        return DEFAULT_SURFACE_OFFSET
    if isinstance(value, str):
        if value not in SURFACE_OFFSET_MODES:
            raise VicDrakeError(
                f"surface offset must be a number of m or one of "
                f"{list(SURFACE_OFFSET_MODES)}; got {value!r}"
            )
        return value
    return check_surface_offset(value, "surface offset")


def surface_calibration(real, phantom, offset=None) -> dict:
    """The surface offset for a real log's replay, and the evidence the log holds.

    Args:
        real: the log's canonical frame.
        phantom: the published map.
        offset: a number of m (used as given), "auto" or "none" (see the
            module doc); None for DEFAULT_SURFACE_OFFSET.

    Returns:
        dict: ``offset_m`` (applied), ``source`` (one of
        :data:`SURFACE_OFFSET_SOURCES`), ``first_contact`` (the
        :class:`~vic_drake.analysis.surface_offset.SurfaceOffset` of the log
        or None) and ``controller_map_offset_m`` (or None).
    """
    first = first_contact_offset(real, phantom)
    out = {
        "first_contact": first,
        "controller_map_offset_m": controller_map_offset(real, phantom),
    }
    offset = parse_surface_offset(offset)
    if offset == "none":
        return {**out, "offset_m": 0.0, "source": "none"}
    if offset != "auto":
        return {**out, "offset_m": offset, "source": "given"}
    if first is not None and _plausible(first):
        return {**out, "offset_m": first.offset_m, "source": "first contact"}
    return {**out, "offset_m": RIG_SURFACE_OFFSET_M, "source": "rig default"}


def _plausible(first) -> bool:
    """A first-contact estimate "auto" may use: in range and a tight fit."""
    return (
        abs(first.offset_m) <= MAX_SURFACE_OFFSET_M
        and first.sigma_m <= MAX_FIRST_CONTACT_SIGMA_M
    )


def rig_surface_offset(bags, phantom) -> dict:
    """The rig's default offset from calibration logs: the mean of their
    first-contact offsets.

    Args:
        bags: scan log folders; those without a free-space approach are
            listed as unused.
        phantom: the published map.

    Returns:
        dict: ``offset_m`` (mean), ``spread_m`` (sample std, 0 for one log),
        ``per_log`` {folder name: offset m}, ``unused`` [folder names].

    Raises:
        VicDrakeError: no log has a first contact from free space.
    """
    per_log, unused = {}, []
    for bag in bags:
        first = first_contact_offset(real_to_canonical(read_bag(bag)), phantom)
        if first is None:
            unused.append(Path(bag).name)
        else:
            per_log[Path(bag).name] = first.offset_m
    if not per_log:
        raise VicDrakeError(
            "none of the logs approaches the phantom from free space; "
            "cannot calibrate the surface"
        )
    values = np.array(list(per_log.values()))
    spread = float(np.std(values, ddof=1)) if values.size > 1 else 0.0
    return {
        "offset_m": float(np.mean(values)),
        "spread_m": spread,
        "per_log": per_log,
        "unused": unused,
    }


__all__ = [
    "DEFAULT_SURFACE_OFFSET",
    "MAX_FIRST_CONTACT_SIGMA_M",
    "MAX_SURFACE_OFFSET_M",
    "SURFACE_OFFSET_MODES",
    "SURFACE_OFFSET_SOURCES",
    "check_surface_offset",
    "parse_surface_offset",
    "rig_surface_offset",
    "surface_calibration",
]
