"""Tissue models (Hunt-Crossley, Kelvin-Voigt) and phantoms (measured, synthetic)."""

from vic_drake.tissue.models import (
    hunt_crossley_force,
    hunt_crossley_penetration,
    kelvin_voigt_force,
)
from vic_drake.tissue.phantom import (
    GridPhantom,
    Phantom,
    PointLookup,
    SyntheticChestParams,
    SyntheticChestPhantom,
    TissueSample,
    load_phantom,
)

__all__ = [
    "GridPhantom",
    "Phantom",
    "PointLookup",
    "SyntheticChestParams",
    "SyntheticChestPhantom",
    "TissueSample",
    "hunt_crossley_force",
    "hunt_crossley_penetration",
    "kelvin_voigt_force",
    "load_phantom",
]
