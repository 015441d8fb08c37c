"""Tissue models (Hunt-Crossley, its relaxing variant, Kelvin-Voigt) and phantoms."""

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
from vic_drake.tissue.relaxation import (
    DEFAULT_RELAXATION,
    DEFAULT_UPDATE_PERIOD_S,
    TISSUE_LAWS,
    RelaxationParams,
    relaxation_history,
    relaxation_input,
    relaxation_step,
    relaxing_hunt_crossley_force,
    tissue_relaxation,
)

__all__ = [
    "DEFAULT_RELAXATION",
    "DEFAULT_UPDATE_PERIOD_S",
    "TISSUE_LAWS",
    "RelaxationParams",
    "relaxation_history",
    "relaxation_input",
    "relaxation_step",
    "relaxing_hunt_crossley_force",
    "tissue_relaxation",
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
