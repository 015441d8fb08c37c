"""The real phantom's surface against the published map: the rig's calibration.

:func:`surface_calibration` decides how compare-real raises the simulated
tissue (the controller keeps reading the published map, as the real one read
its own): a number given by the caller; "none", no offset; "anchors", from
the log's own anchors outside the scored window, each used only when
plausible (within +-MAX_SURFACE_OFFSET_M, 1-sigma at most
MAX_FIRST_CONTACT_SIGMA_M; the lift-off also with a fit modulus within a
factor MAX_LIFT_OFF_KAPPA_RATIO of the map's kappa):

- the first contact from free space
  (:func:`vic_drake.analysis.surface_offset.first_contact_offset`) and the
  final lift-off (:func:`vic_drake.analysis.lift_off.lift_off_offset`), at
  least MIN_PROFILE_SPAN_M apart in x: a profile linear in x between them,
  held beyond (:func:`vic_drake.tissue.phantom.distorted.with_surface_profile`);
- one of them: its offset, constant;
- neither: the rig's default :data:`vic_drake.realdata.RIG_SURFACE_OFFSET_M`
  (which :func:`rig_surface_offset` recomputes from the calibration logs).

"placement": when the phantom rests (compare-real does not replay its
motion), the plane of its in-contact surface
(:func:`vic_drake.analysis.surface_placement.fit_surface_placement`: offset
and tilt along the track, read from the log's force at the map's kappa),
applied by :func:`placed_surface`
(:func:`vic_drake.tissue.phantom.distorted.with_surface_plane`); when it
moves, or no plausible plane is found, the anchors.

"auto" is :data:`AUTO_MODE` ("placement"); compare-real's default is
:data:`DEFAULT_SURFACE_OFFSET` ("auto"). Why: docs/decisions.md, "Surface
calibration of compare-real" and "Phantom placement from the in-contact
surface".
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.lift_off import lift_off_offset
from vic_drake.analysis.surface_offset import (
    controller_map_offset,
    first_contact_offset,
)
from vic_drake.analysis.surface_placement import fit_surface_placement
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import RIG_SURFACE_OFFSET_M, read_bag
from vic_drake.tissue.relaxation import DEFAULT_RELAXATION

#: Largest offset accepted, m (the scenario's map errors allow +-0.02 m).
MAX_SURFACE_OFFSET_M = 0.02
#: The words compare-real's surface offset takes besides a number: "anchors"
#: (the first contact and the lift-off, else the rig default), "placement"
#: (the plane of the in-contact surface when the phantom rests, else the
#: anchors), "auto" (:data:`AUTO_MODE`), "none".
SURFACE_OFFSET_MODES = ("none", "auto", "anchors", "placement")
#: What "auto" stands for.
AUTO_MODE = "placement"
#: compare-real's default (docs/decisions.md, "Surface calibration of
#: compare-real").
DEFAULT_SURFACE_OFFSET = "auto"
#: Largest 1-sigma of a first-contact estimate that "anchors" uses, m; a
#: looser fit (a noisy or irregular approach) falls back on the rig default.
MAX_FIRST_CONTACT_SIGMA_M = 0.0005
#: Largest ratio (either way) between a lift-off fit's modulus and the map's
#: kappa that "anchors" uses: a lift that does not follow the tissue model the
#: estimate corrects with is no evidence of the surface (docs/decisions.md,
#: "Lift-off surface of the real logs").
MAX_LIFT_OFF_KAPPA_RATIO = 1.5
#: Shortest distance in x between the two anchors of a surface profile, m.
MIN_PROFILE_SPAN_M = 0.02
#: Where the offset came from (``surface_offset_source`` of compare-real).
SURFACE_OFFSET_SOURCES = (
    "none",
    "given",
    "first contact",
    "lift-off",
    "first contact + lift-off",
    "rig default",
    "placement",
)


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


def surface_calibration(
    real, phantom, offset=None, *, relaxation=DEFAULT_RELAXATION
) -> dict:
    """The surface offset for a real log's replay, and the evidence the log holds.

    The placement plane is only read here (``placement``); whether the
    phantom rests, and so whether the plane is used, is known after the
    motion estimate: :func:`placed_surface` applies it.

    Args:
        real: the log's canonical frame.
        phantom: the published map.
        offset: a number of m (used as given), one of
            :data:`SURFACE_OFFSET_MODES` (see the module doc); None for
            DEFAULT_SURFACE_OFFSET.
        relaxation: the simulated tissue's relaxation (None: plain
            Hunt-Crossley), which the lift-off estimate and the apparent
            surface of the placement correct for.

    Returns:
        dict: ``offset_m`` (applied; with a profile, the mean of its two
        anchors), ``source`` (one of :data:`SURFACE_OFFSET_SOURCES`),
        ``profile`` (None, or ``{"x_m": [2], "offset_m": [2]}`` in increasing
        x), ``first_contact`` (the
        :class:`~vic_drake.analysis.surface_offset.SurfaceOffset` of the log
        or None), ``lift_off`` (the
        :class:`~vic_drake.analysis.lift_off.LiftOff` or None),
        ``controller_map_offset_m`` (or None), ``placement`` (the
        :class:`~vic_drake.analysis.surface_placement.SurfacePlacement` or
        None), ``plane`` (None until :func:`placed_surface`) and
        ``placement_wanted`` (the mode asks for the plane when the phantom
        rests).
    """
    first = first_contact_offset(real, phantom)
    lift = lift_off_offset(real, phantom, relaxation=relaxation)
    offset = parse_surface_offset(offset)
    mode = AUTO_MODE if offset == "auto" else offset
    out = {
        "first_contact": first,
        "lift_off": lift,
        "controller_map_offset_m": controller_map_offset(real, phantom),
        "placement": fit_surface_placement(real, phantom, relaxation=relaxation),
        "profile": None,
        "plane": None,
        "placement_wanted": mode == "placement",
    }
    if mode == "none":
        return {**out, "offset_m": 0.0, "source": "none"}
    if isinstance(mode, float):
        return {**out, "offset_m": mode, "source": "given"}
    use_first = first is not None and _plausible(first)
    use_lift = lift is not None and _plausible_lift_off(lift)
    if use_first and use_lift and abs(lift.x_m - first.x_m) >= MIN_PROFILE_SPAN_M:
        profile = _profile(real, phantom, first, lift, relaxation)
        if profile is not None:
            return {
                **out,
                "lift_off": profile.pop("lift_off"),
                "profile": profile,
                "offset_m": float(np.mean(profile["offset_m"])),
                "source": "first contact + lift-off",
            }
    if use_first:
        return {**out, "offset_m": first.offset_m, "source": "first contact"}
    if use_lift:
        return {**out, "offset_m": lift.offset_m, "source": "lift-off"}
    return {**out, "offset_m": RIG_SURFACE_OFFSET_M, "source": "rig default"}


def placed_surface(surface: dict, *, resting: bool) -> dict:
    """``surface`` (of :func:`surface_calibration`) with the placement plane
    applied when the mode asks for it, the phantom rests (its motion is not
    replayed: a moving phantom's in-contact surface is placement plus motion)
    and the plane is plausible (within +-MAX_SURFACE_OFFSET_M at both ends of
    the track); else ``surface`` itself.

    The result's ``plane`` is ``{"offset_m", "gradient", "origin_m"}``
    (:func:`~vic_drake.tissue.phantom.distorted.with_surface_plane`'s
    arguments), ``offset_m`` the plane's offset at its origin, ``source``
    "placement", ``profile`` None.
    """
    placement = surface["placement"]
    if not (surface["placement_wanted"] and resting and placement is not None):
        return surface
    if not _plausible_placement(placement):
        return surface
    return {
        **surface,
        "offset_m": placement.offset_m,
        "source": "placement",
        "profile": None,
        "plane": {
            "offset_m": placement.offset_m,
            "gradient": placement.gradient,
            "origin_m": (placement.x0_m, placement.y0_m),
        },
    }


def _plausible_placement(placement) -> bool:
    """A plane "placement" may use: within +-MAX_SURFACE_OFFSET_M at both ends
    of the span it was fitted on (first and last bin centre)."""
    start = placement.start_m
    ends = placement.offset_m + placement.slope_m_per_m * np.array(
        [start, start + placement.span_m]
    )
    return bool(
        np.all(np.isfinite(ends)) and np.all(np.abs(ends) <= MAX_SURFACE_OFFSET_M)
    )


def _profile(real, phantom, first, lift, relaxation):
    """The two-anchor profile, the lift-off re-read with the profile as its
    relaxation history (two passes); None if the re-read is not plausible."""
    for _ in range(2):
        xs, offs = _anchors(first, lift)
        history = np.interp(real["x_m"].to_numpy(float), xs, offs)
        lift = lift_off_offset(
            real, phantom, relaxation=relaxation, history_offset_m=history
        )
        if lift is None or not _plausible_lift_off(lift):
            return None
    xs, offs = _anchors(first, lift)
    return {"x_m": xs, "offset_m": offs, "lift_off": lift}


def _anchors(first, lift) -> tuple[list[float], list[float]]:
    """The two anchors' x and offsets, m, in increasing x."""
    pairs = sorted([(first.x_m, first.offset_m), (lift.x_m, lift.offset_m)])
    return [float(x) for x, _ in pairs], [float(o) for _, o in pairs]


def _plausible(first) -> bool:
    """A first-contact estimate "anchors" may use: in range and a tight fit."""
    return (
        abs(first.offset_m) <= MAX_SURFACE_OFFSET_M
        and first.sigma_m <= MAX_FIRST_CONTACT_SIGMA_M
    )


def _plausible_lift_off(lift) -> bool:
    """A lift-off estimate "anchors" may use: as a first contact, and the lift
    follows the tissue model (fit modulus near the map's kappa)."""
    return _plausible(lift) and (
        1.0 / MAX_LIFT_OFF_KAPPA_RATIO <= lift.kappa_scale <= MAX_LIFT_OFF_KAPPA_RATIO
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
    "AUTO_MODE",
    "DEFAULT_SURFACE_OFFSET",
    "MAX_FIRST_CONTACT_SIGMA_M",
    "MAX_LIFT_OFF_KAPPA_RATIO",
    "MAX_SURFACE_OFFSET_M",
    "MIN_PROFILE_SPAN_M",
    "SURFACE_OFFSET_MODES",
    "SURFACE_OFFSET_SOURCES",
    "check_surface_offset",
    "parse_surface_offset",
    "placed_surface",
    "rig_surface_offset",
    "surface_calibration",
]
