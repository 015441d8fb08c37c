"""A population of synthetic chests: one patient's phantom, and seeded draws.

A patient is the reference synthetic chest
(:class:`~vic_drake.tissue.phantom.synthetic_chest.SyntheticChestParams`,
whose values are anchored on the measured phantom) changed by a few
anatomical factors, each with a reference value (the measured phantom) and a
population range (:data:`POPULATION_RANGES`):

- ``kappa_scale``, ``lam_scale``: soft tissue and ribs stiffer or softer,
  more or less viscous (multiply kappa and lambda everywhere);
- ``rib_stiffness_scale``: the ribs' stiffness rise above the soft tissue;
- ``rib_depth_m``: soft tissue over the ribs; a deeper rib shows a smaller
  and wider stiffness band (rise x ref/depth, band width x sqrt(depth/ref));
- ``rib_spacing_scale``, ``rib_width_scale``: intercostal spacing (about the
  middle rib) and the rib band's half-width;
- ``soft_tissue_offset_m``: a thicker or thinner body wall raises or lowers
  the surface;
- ``curvature_scale``: the chest's dome curvature along x and y;
- ``shoulder_scale``: height of the shoulder (the hump beside the scan);
- ``texture_seed``: the soft tissue's own texture.

The ranges are modelling choices (documented in docs/decisions.md,
"Patient population"): +-30 % on the tissue parameters, as the issue's map
errors, and anatomical spreads of a few millimetres.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom.synthetic_chest import (
    SyntheticChestParams,
    SyntheticChestPhantom,
)

#: Soft tissue over the ribs of the reference phantom, m.
REFERENCE_RIB_DEPTH_M = 0.010

#: Each patient factor: (reference value, population low, population high).
POPULATION_RANGES: dict[str, tuple[float, float, float]] = {
    "kappa_scale": (1.0, 0.7, 1.3),
    "lam_scale": (1.0, 0.7, 1.3),
    "rib_stiffness_scale": (1.0, 0.7, 1.3),
    "rib_depth_m": (REFERENCE_RIB_DEPTH_M, 0.006, 0.016),
    "rib_spacing_scale": (1.0, 0.85, 1.15),
    "rib_width_scale": (1.0, 0.75, 1.25),
    "soft_tissue_offset_m": (0.0, -0.004, 0.004),
    "curvature_scale": (1.0, 0.6, 1.4),
    # The reference chest's hump (fitted to the measured map) x 0.6-1.4.
    "shoulder_scale": (1.0, 0.6, 1.4),
}

#: Hard limits of each factor (what a scenario may set): physical sense.
FACTOR_LIMITS: dict[str, tuple[float, float]] = {
    "kappa_scale": (0.1, 5.0),
    "lam_scale": (0.1, 5.0),
    "rib_stiffness_scale": (0.0, 5.0),
    "rib_depth_m": (0.002, 0.05),
    "rib_spacing_scale": (0.5, 1.5),
    "rib_width_scale": (0.2, 3.0),
    "soft_tissue_offset_m": (-0.02, 0.02),
    "curvature_scale": (0.0, 3.0),
    "shoulder_scale": (0.0, 3.0),
}


def check_patient_factors(factors: dict[str, float], owner: str = "patient") -> None:
    """Raises VicDrakeError naming a missing, unknown or out-of-limit factor."""
    for name in factors:
        if name not in FACTOR_LIMITS and name != "texture_seed":
            raise VicDrakeError(
                f"{owner}: unknown factor {name!r}; allowed: "
                f"{sorted([*FACTOR_LIMITS, 'texture_seed'])}"
            )
    for name, (low, high) in FACTOR_LIMITS.items():
        value = factors.get(name, POPULATION_RANGES[name][0])
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise VicDrakeError(f"{owner}.{name} must be a number; got {value!r}")
        if not (math.isfinite(value) and low <= value <= high):
            raise VicDrakeError(
                f"{owner}.{name} must be in [{low}, {high}]; got {value!r}"
            )


def patient_chest_params(
    factors: dict[str, float], base: SyntheticChestParams | None = None
) -> SyntheticChestParams:
    """The synthetic chest of one patient.

    Args:
        factors: patient factors by name (missing ones take their reference
            value); ``texture_seed`` (int) optional.
        base: the reference chest (default: SyntheticChestParams()).
    """
    check_patient_factors(factors)
    base = base or SyntheticChestParams()
    f = {name: ref for name, (ref, _, _) in POPULATION_RANGES.items()}
    f.update({k: v for k, v in factors.items() if k != "texture_seed"})
    depth_ratio = REFERENCE_RIB_DEPTH_M / f["rib_depth_m"]
    rise = (base.kappa_rib - base.kappa_soft) * f["rib_stiffness_scale"] * depth_ratio
    soft = base.kappa_soft * f["kappa_scale"]
    offsets = np.asarray(base.rib_offsets_x_m, float)
    middle = float(np.mean(offsets))
    spaced = middle + (offsets - middle) * f["rib_spacing_scale"]
    return dataclasses.replace(
        base,
        kappa_soft=soft,
        kappa_rib=soft + rise * f["kappa_scale"],
        # lambda = lam_ref * (kappa / kappa_ref)^p: scaling kappa_ref with
        # kappa keeps lambda's own scale lam_scale.
        kappa_ref=base.kappa_ref * f["kappa_scale"],
        lam_ref=base.lam_ref * f["lam_scale"],
        rib_offsets_x_m=tuple(float(o) for o in spaced),
        rib_sigma_m=base.rib_sigma_m
        * f["rib_width_scale"]
        * math.sqrt(1.0 / depth_ratio),
        top_z_m=base.top_z_m + f["soft_tissue_offset_m"],
        curvature_x_per_m=base.curvature_x_per_m * f["curvature_scale"],
        curvature_y_per_m=base.curvature_y_per_m * f["curvature_scale"],
        shoulder_rise_m=base.shoulder_rise_m * f["shoulder_scale"],
        texture_seed=int(factors.get("texture_seed", base.texture_seed)),
    )


def patient_phantom(factors: dict[str, float]) -> SyntheticChestPhantom:
    """The synthetic chest phantom of one patient (see :func:`patient_chest_params`)."""
    phantom = SyntheticChestPhantom(patient_chest_params(factors))
    phantom.name = "patient"
    return phantom


def sample_patient(seed: int) -> dict[str, float]:
    """One patient drawn from the population, uniformly in each range.

    Args:
        seed: the patient's seed (the same seed gives the same patient).

    Returns:
        {factor: value} for every factor of :data:`POPULATION_RANGES`, plus
        ``texture_seed``.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise VicDrakeError(f"patient seed must be an integer >= 0; got {seed!r}")
    rng = np.random.default_rng([int(seed), 0x9A71E47])
    out = {
        name: float(rng.uniform(low, high))
        for name, (_, low, high) in POPULATION_RANGES.items()
    }
    out["texture_seed"] = int(rng.integers(0, 2**31 - 1))
    return out


__all__ = [
    "FACTOR_LIMITS",
    "POPULATION_RANGES",
    "REFERENCE_RIB_DEPTH_M",
    "check_patient_factors",
    "patient_chest_params",
    "patient_phantom",
    "sample_patient",
]
