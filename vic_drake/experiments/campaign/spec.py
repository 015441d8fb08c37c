"""The campaign spec: a base scenario, runs, seed, duration and factors.

A campaign YAML (``campaigns/*.yaml``) is loaded with ``yaml_load_typed``
into :class:`CampaignSpec`; :func:`load_campaign_spec` checks it and every
factor's whole range against the base scenario before any run starts
(:func:`check_factor_ranges`), so a bad range or label fails whatever
``runs`` and ``seed`` are.

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

import copy
import dataclasses
import math
import os
from dataclasses import dataclass
from operator import attrgetter
from pathlib import Path

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign.fields import (
    apply_controller,
    field_value,
    set_field,
)
from vic_drake.experiments.scan_diagram import (
    initial_joint_positions,
    load_scenario_phantom,
)
from vic_drake.run_limits import MAX_EXTRA_DURATION_S
from vic_drake.scenario import Scenario, as_plain, load_scenario
from vic_drake.scenario.io import load_typed

#: The distributions a factor may have.
DISTRIBUTIONS = ("uniform", "normal", "choice", "grid")

#: The factor name that selects a controller with the paper's settings.
CONTROLLER_FACTOR = "controller"

#: An unclipped normal factor (``low`` >= ``high``) has no finite bounds; its
#: range is checked at mean -/+ this many standard deviations. A draw beyond
#: has a probability of 2e-9 per run, and still fails that run's own check
#: in :func:`~.plan.plan_campaign`, before any run starts; clip the normal
#: with ``low`` and ``high`` to make the check exact.
NORMAL_CHECK_STDS = 6.0


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
            levels = self.levels
            twice = [v for i, v in enumerate(levels) if v in levels[:i]]
            if self.dist == "grid" and twice:  # A choice may weight by repeating.
                raise VicDrakeError(
                    f"{where} ({self.field}): the grid lists {twice[0]!r} more than "
                    "once; give each level once (a repeated cell runs the same "
                    "scans twice as if they were two arms)"
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

    def extremes(self) -> list[tuple[str, object]]:
        """The ends of what the factor can draw, as (which, value) pairs.

        uniform: low and high; a clipped normal: its clip bounds (reached
        whenever a draw falls beyond them); an unclipped normal: mean -/+
        :data:`NORMAL_CHECK_STDS` std; choice and grid: every level.
        """
        if self.dist in ("choice", "grid"):
            which = "label" if self.labels else "value"
            return [(which, v) for v in dict.fromkeys(self.levels)]
        if self.dist == "normal" and not self.low < self.high:
            k = NORMAL_CHECK_STDS
            return [
                (f"mean - {k:g} std", self.mean - k * self.std),
                (f"mean + {k:g} std", self.mean + k * self.std),
            ]
        return [("low", float(self.low)), ("high", float(self.high))]


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
    check_factor_ranges(spec, load_scenario(base), where)
    return spec, base


#: What the start of a run (:func:`_start`) reads of its scenario.
_START_PARTS = ("trajectory", "station", "phantom", "variations.patient")


def _start(scenario: Scenario, seen: set, field: str = "") -> Scenario:
    """Validates a scenario and checks that a run of it can start: the IK of
    the probe's start pose and the phantom (a measured map needs the data
    folder), which a run meets only on its worker, as an error row. Those
    two are checked once per distinct start (``seen``), and not for a
    ``field`` outside :data:`_START_PARTS` (the start is then its arm's)."""
    scenario.validate()
    if field and not field.startswith(tuple(f"{p}." for p in _START_PARTS)):
        return scenario
    key = repr([as_plain(attrgetter(p)(scenario)) for p in _START_PARTS])
    if key not in seen:
        try:
            initial_joint_positions(scenario)
            load_scenario_phantom(scenario)
        except VicDrakeError as exc:
            raise VicDrakeError(f"a run with it cannot start: {exc}") from None
        seen.add(key)
    return scenario


def check_factor_ranges(spec: CampaignSpec, base: Scenario, where: str) -> None:
    """Checks every value each factor can draw against the scenario's checks.

    Each factor's :meth:`Factor.extremes` (both ends of a range, every label
    or value of a choice or grid) is set, with the planner's own
    :func:`~.fields.set_field` (or :func:`~.fields.apply_controller`), on a
    copy of the base scenario as a run starts it (the campaign's
    ``duration_s``; with ``population``, the patient enabled, as the
    reference chest; with a controller factor, on each of its arms, as a run
    applies the controller before the other factors); the copy is then
    validated and its start checked (:func:`_start`). The result depends on
    the spec and the base only, not on ``runs`` or ``seed``.

    Not caught here, so still by each run's own check in
    :func:`~.plan.plan_campaign` (before any run, but only for the draws
    made): a bad combination of two factors (one field's bound depending on
    another's value, such as ``stiffness_source`` online needing the
    reference's dither, or ``watchdog.dead_window_s`` against
    ``station.sensor_period_s``); a field whose valid values are not one
    interval (both ends valid, a value between them not); a factor against a
    drawn patient rather than the reference chest; an unclipped normal's
    draw beyond :data:`NORMAL_CHECK_STDS`. A start that fails between two
    good ends (an IK target crossing the arm's unreachable core) is not
    caught before its run at all: it is that run's error row.

    Raises:
        VicDrakeError: naming the spec, the factor (index and field), the
            value (low, high or label) and the scenario's own message.
    """
    seen: set = set()
    end = float(base.trajectory.end_time_s)
    limit = max(float(base.total_duration_s), end + 1.0) + MAX_EXTRA_DURATION_S
    if spec.duration_s > limit:  # The probe only holds still after its end.
        raise VicDrakeError(
            f"{where}: duration_s {spec.duration_s:g} s is far beyond the base "
            f"scenario: its trajectory ends at {end:.1f} s; give at most "
            f"{limit:.1f} s (each of the {spec.runs} runs is simulated that long)"
        )
    start = copy.deepcopy(base)
    start.duration_s = float(spec.duration_s)  # As run_scenario does.
    if spec.population:
        start.variations.patient.enabled = True
    try:
        _start(start, seen)
    except VicDrakeError as exc:
        raise VicDrakeError(
            f"{where}: the base scenario {spec.base_scenario!r}, with the "
            f"campaign's duration_s and population, fails: {exc}"
        ) from None
    for i, f in enumerate(spec.factors):
        if f.field != CONTROLLER_FACTOR:
            _check_field_kind(where, i, f, start)
    arms = {"": start}
    for i, f in enumerate(spec.factors):
        if f.field == CONTROLLER_FACTOR:
            arms = {v: _arm(where, i, f, w, v, start, seen) for w, v in f.extremes()}
    for i, f in enumerate(spec.factors):
        if f.field == CONTROLLER_FACTOR:
            continue
        for which, value in f.extremes():
            errors = {}
            for arm, scenario in arms.items():
                try:
                    s = copy.deepcopy(scenario)
                    set_field(s, f.field, value)
                    _start(s, seen, f.field)
                except VicDrakeError as exc:
                    errors[arm] = exc
            if errors:
                # Name the arms only when some of them take the value.
                only = f" (with controller {', '.join(errors)})"
                only = only if len(errors) < len(arms) else ""
                raise _range_error(
                    where, i, f, which, value, next(iter(errors.values())), only
                )


def _check_field_kind(where: str, i: int, f: Factor, base: Scenario) -> None:
    """The factor's field exists, and an integer field is drawn from levels:
    a uniform or normal draw would be rounded in the scenario while the row
    records the unrounded number, and its levels drawn unevenly."""
    try:
        current = field_value(base, f.field)
    except VicDrakeError as exc:
        raise VicDrakeError(f"{where}: factors[{i}]: {exc}") from None
    integer = isinstance(current, int) and not isinstance(current, bool)
    if integer and f.dist in ("uniform", "normal"):
        raise VicDrakeError(
            f"{where}: factors[{i}] ({f.field}) is an integer field: draw it with "
            f"dist grid or choice and its values (e.g. values: [{current}, ...]), "
            f"not {f.dist}"
        )


def _arm(where, i, f, which, label, start, seen) -> Scenario:
    try:
        s = copy.deepcopy(start)
        apply_controller(s, label)
        return _start(s, seen)
    except VicDrakeError as exc:
        raise _range_error(where, i, f, which, label, exc, "") from None


def _range_error(where, i, f, which, value, exc, only) -> VicDrakeError:
    hint = (
        " (an unclipped normal: give it low and high to clip it)"
        if which.startswith("mean")
        else ""
    )
    return VicDrakeError(
        f"{where}: factors[{i}] ({f.field}): its {which} {value!r}{only} is "
        f"refused{hint}: {exc}. Every value a factor can draw is checked when "
        "the spec loads, whatever runs and seed are (both ends of a range, every "
        "label or value of a choice or grid, each set alone on the base "
        "scenario); narrow the range or change the labels."
    )


__all__ = [
    "CONTROLLER_FACTOR",
    "DISTRIBUTIONS",
    "NORMAL_CHECK_STDS",
    "CampaignSpec",
    "Factor",
    "check_factor_ranges",
    "load_campaign_spec",
]
