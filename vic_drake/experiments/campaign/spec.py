"""The campaign spec: a base scenario, runs, seed, duration and factors.

A campaign YAML (``campaigns/*.yaml``) is loaded with ``yaml_load_typed``
into :class:`CampaignSpec`; :func:`load_campaign_spec` checks it and every
factor against the base scenario before any run starts.

A factor sets one scenario field (a dotted path such as
``variations.motion.breathing.amplitude_m`` or ``variations.sensor_faults.bias_N[2]``)
or ``controller`` (the paper's settings of cs, cf, vs-cf or vs-vf), drawn
from a distribution:

- ``uniform``: ``low``..``high``;
- ``normal``: ``mean``, ``std``, clipped to [``low``, ``high``] if ``low`` < ``high``;
- ``choice``: one of ``values`` (numbers) or ``labels`` (strings), at random;
- ``grid``: every one of ``values`` or ``labels`` in turn; several grid
  factors make a full factorial, cycled over the runs (``runs`` must be a
  multiple of the grid's size, so every cell gets as many runs).

With ``population: true`` each run draws a synthetic patient
(:func:`vic_drake.tissue.phantom.population.sample_patient`); with grid
factors, every cell of one round of the grid gets the same patient, so
controllers are compared on the same patients.

With ``paired: true`` (it needs a grid factor) every cell of one round of
the grid gets the same draws of every other factor too, and the same run
seed (breathing, sensor noise, spikes and dropouts): the arms are compared
under the same conditions, run for run (common random numbers). Without
it, each run draws its own.
"""

import dataclasses
import math
import os
from dataclasses import dataclass
from pathlib import Path

from vic_drake.errors import VicDrakeError
from vic_drake.scenario.io import load_typed

#: The distributions a factor may have.
DISTRIBUTIONS = ("uniform", "normal", "choice", "grid")

#: The factor name that selects a controller with the paper's settings.
CONTROLLER_FACTOR = "controller"


@dataclass
class Factor:
    """One varied field and its distribution (see the module docstring)."""

    field: str = ""  # Dotted scenario path, or "controller".
    dist: str = "uniform"  # uniform | normal | choice | grid.
    low: float = 0.0  # uniform: lower bound; normal: clip low.
    high: float = 0.0  # uniform: upper bound; normal: clip high.
    mean: float = 0.0  # normal: mean.
    std: float = 0.0  # normal: standard deviation (> 0).
    values: list[float] = dataclasses.field(
        default_factory=list
    )  # choice/grid numbers.
    labels: list[str] = dataclasses.field(default_factory=list)  # choice/grid strings.

    def validate(self, where: str) -> "Factor":
        """Checks the distribution's parameters; returns self."""
        if not isinstance(self.field, str) or not self.field:
            raise VicDrakeError(f"{where}.field must name a scenario field")
        if self.dist not in DISTRIBUTIONS:
            raise VicDrakeError(
                f"{where}.dist must be one of {list(DISTRIBUTIONS)}; got {self.dist!r}"
            )
        numbers = (self.low, self.high, self.mean, self.std, *self.values)
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in numbers):
            raise VicDrakeError(f"{where} ({self.field}): numbers must be finite")
        if self.dist == "uniform" and not self.low < self.high:
            raise VicDrakeError(
                f"{where} ({self.field}): uniform needs low < high; "
                f"got low {self.low}, high {self.high}"
            )
        if self.dist == "normal" and not self.std > 0:
            raise VicDrakeError(
                f"{where} ({self.field}): normal needs std > 0; got {self.std}"
            )
        if self.dist in ("choice", "grid"):
            if bool(self.values) == bool(self.labels):
                raise VicDrakeError(
                    f"{where} ({self.field}): {self.dist} needs either values "
                    "(numbers) or labels (strings), not both"
                )
        elif self.values or self.labels:
            raise VicDrakeError(
                f"{where} ({self.field}): values/labels are for choice and grid only"
            )
        return self

    @property
    def levels(self) -> list:
        """The values of a choice or grid factor."""
        return list(self.labels) if self.labels else [float(v) for v in self.values]


@dataclass
class CampaignSpec:
    """A campaign: many runs of a base scenario with sampled factors."""

    name: str = "campaign"  # Label (file names, reports).
    description: str = ""
    # Base scenario YAML, relative to the spec file (or absolute).
    base_scenario: str = "../diagrams/nominal_vs_vf_synthetic.yaml"
    runs: int = 16  # Number of runs.
    seed: int = 0  # Campaign seed: run i draws from (seed, i).
    duration_s: float = 3.0  # Simulated time of each run, s.
    force_limit_N: float = 15.0  # The safety limit on the force on the patient, N.
    population: bool = False  # Each run draws a synthetic patient.
    # The cells of a grid round share every other draw and the run seed.
    paired: bool = False
    factors: list[Factor] = dataclasses.field(default_factory=list)

    def validate(self) -> "CampaignSpec":
        o = "campaign"
        if not isinstance(self.name, str) or not self.name.replace("_", "").isalnum():
            raise VicDrakeError(
                f"{o}.name must be letters, digits and '_'; got {self.name!r}"
            )
        for key, low in (("runs", 1), ("seed", 0)):
            v = getattr(self, key)
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise VicDrakeError(f"{o}.{key} must be an integer >= {low}; got {v!r}")
        for key in ("duration_s", "force_limit_N"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v > 0):
                raise VicDrakeError(f"{o}.{key} must be > 0; got {v!r}")
        seen = set()
        for i, f in enumerate(self.factors):
            f.validate(f"{o}.factors[{i}]")
            if f.field in seen:
                raise VicDrakeError(f"{o}.factors: {f.field!r} appears twice")
            seen.add(f.field)
        for key in ("population", "paired"):
            if not isinstance(getattr(self, key), bool):
                raise VicDrakeError(
                    f"{o}.{key} must be true or false; got {getattr(self, key)!r}"
                )
        if self.paired and not self.grid_size:
            raise VicDrakeError(
                f"{o}.paired needs a grid factor (its cells are what is paired); "
                "the factors have none"
            )
        if self.grid_size and self.runs % self.grid_size:
            raise VicDrakeError(
                f"{o}.runs ({self.runs}) must be a multiple of the grid's size "
                f"({self.grid_size} cells), so every cell gets as many runs"
            )
        return self

    @property
    def grid_size(self) -> int:
        n = 1
        for f in self.factors:
            if f.dist == "grid":
                n *= len(f.levels)
        return n if any(f.dist == "grid" for f in self.factors) else 0


def load_campaign_spec(path: str | os.PathLike) -> tuple[CampaignSpec, Path]:
    """Loads and checks a campaign YAML.

    Returns:
        (spec, base scenario path resolved against the spec's folder).

    Raises:
        VicDrakeError: a missing file, an unknown key, a bad value.
    """
    path = Path(path)
    if not path.is_file():
        raise VicDrakeError(f"campaign spec {str(path)!r} does not exist")
    where = f"campaign spec {str(path)!r}"
    # The scenario loader's treatment: the bad field named, the allowed ones
    # listed for an unknown field.
    spec = load_typed(
        CampaignSpec,
        {"filename": str(path)},
        where,
        schema_name="vic_drake.experiments.campaign.CampaignSpec",
    )
    try:
        spec.validate()
    except VicDrakeError as exc:
        raise VicDrakeError(f"{where}: {exc}") from None
    base = Path(spec.base_scenario)
    if not base.is_absolute():
        base = (path.parent / base).resolve()
    if not base.is_file():
        raise VicDrakeError(
            f"campaign {spec.name!r}: base_scenario {spec.base_scenario!r} "
            f"({str(base)!r}) does not exist"
        )
    return spec, base


__all__ = [
    "CONTROLLER_FACTOR",
    "DISTRIBUTIONS",
    "CampaignSpec",
    "Factor",
    "load_campaign_spec",
]
