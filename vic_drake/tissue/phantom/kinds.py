"""The phantom kinds a scenario can name, and :func:`load_phantom`."""

from __future__ import annotations

import os

from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom.base import Phantom
from vic_drake.tissue.phantom.grid import GridPhantom
from vic_drake.tissue.phantom.synthetic_chest import SyntheticChestPhantom

PHANTOM_KINDS = ("synthetic", "measured")


def load_phantom(
    kind: str = "synthetic",
    *,
    data_dir: str | os.PathLike | None = None,
    lookup: str = "bilinear",
) -> Phantom:
    """Returns the phantom of the given kind ("synthetic" or "measured")."""
    if kind == "synthetic":
        return SyntheticChestPhantom()
    if kind == "measured":
        return GridPhantom.from_data_dir(data_dir, lookup=lookup)
    raise VicDrakeError(f"phantom kind must be one of {PHANTOM_KINDS}, got {kind!r}")
