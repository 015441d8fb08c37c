"""The runs of a campaign: each run's sampled factors and its exact scenario.

Run i draws from ``numpy.random.default_rng([seed, i])`` only (with
``paired``, from ``[seed, its grid round, 1]``), so its factors do not
depend on the order runs finish in, on the number of workers, or on which
runs a resumed campaign still has to do.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign.fields import (
    CONTROLLERS,
    apply_controller,
    set_field,
)
from vic_drake.experiments.campaign.spec import CONTROLLER_FACTOR, CampaignSpec
from vic_drake.scenario import Scenario, dumps_scenario, loads_scenario
from vic_drake.tissue.phantom.population import sample_patient


@dataclass(frozen=True)
class RunPlan:
    """One run: plain data a worker turns into a simulation.

    The run's scenario is rebuilt from the spec and the base scenario's text
    (:meth:`scenario`), on the worker: deterministic, and the client does
    not pay for writing a thousand scenario YAMLs before the first run.

    Attributes:
        run_id: "run_00012".
        index: position in the campaign.
        factors: {factor name: sampled value}.
        spec: the campaign spec.
        base_yaml: the base scenario, as YAML text.
    """

    run_id: str
    index: int
    factors: dict
    spec: CampaignSpec
    base_yaml: str

    @property
    def duration_s(self) -> float:
        return float(self.spec.duration_s)

    @property
    def force_limit_N(self) -> float:
        return float(self.spec.force_limit_N)

    def scenario(self) -> Scenario:
        """The run's exact scenario (what ``vic-drake scan`` replays)."""
        return run_scenario(self.spec, loads_scenario(self.base_yaml), self.index)[0]


def _draw(spec: CampaignSpec, index: int) -> dict:
    cell = index % spec.grid_size if spec.grid_size else 0
    if spec.paired:  # Every cell of a round draws alike: only the grid differs.
        rng = np.random.default_rng([spec.seed, index // spec.grid_size, 1])
    else:
        rng = np.random.default_rng([spec.seed, index])
    out = {}
    for f in spec.factors:
        if f.dist == "uniform":
            out[f.field] = float(rng.uniform(f.low, f.high))
        elif f.dist == "normal":
            v = float(rng.normal(f.mean, f.std))
            out[f.field] = float(np.clip(v, f.low, f.high)) if f.low < f.high else v
        elif f.dist == "choice":
            out[f.field] = f.levels[int(rng.integers(len(f.levels)))]
        else:  # grid: mixed radix over the grid factors, first one fastest.
            cell, i = divmod(cell, len(f.levels))
            out[f.field] = f.levels[i]
    run_seed = int(rng.integers(0, 2**31 - 1))
    return {"factors": out, "seed": run_seed}


def run_scenario(
    spec: CampaignSpec, base: Scenario, index: int
) -> tuple[Scenario, dict]:
    """The scenario of run ``index`` (validated) and its sampled factors."""
    draw = _draw(spec, index)
    scenario = copy.deepcopy(base)
    run_id = f"run_{index:05d}"
    scenario.name = f"{spec.name}_{run_id}"
    scenario.description = f"campaign {spec.name}, {run_id}"
    scenario.duration_s = float(spec.duration_s)
    # Every random element of the run from its own seed (a factor may override).
    scenario.seed = draw["seed"]
    scenario.variations.sensor_faults.seed = draw["seed"]
    scenario.variations.motion.breathing.seed = draw["seed"]
    factors = dict(draw["factors"])
    if CONTROLLER_FACTOR in factors:
        apply_controller(scenario, factors[CONTROLLER_FACTOR])
    if spec.population:
        # Every cell of the grid sees the same patients (a paired design):
        # the patient depends on the seed and the run's grid round only.
        rounds = index // spec.grid_size if spec.grid_size else index
        patient = sample_patient(
            int(np.random.default_rng([spec.seed, rounds, 7]).integers(2**31 - 1))
        )
        scenario.variations.patient.enabled = True
        for name, value in patient.items():
            setattr(scenario.variations.patient, name, value)
        factors.update({f"patient.{k}": v for k, v in patient.items()})
    for path, value in draw["factors"].items():
        if path != CONTROLLER_FACTOR:
            set_field(scenario, path, value)
    try:
        scenario.validate()
    except VicDrakeError as exc:
        raise VicDrakeError(
            f"campaign {spec.name!r}, {run_id} ({factors}): {exc}"
        ) from None
    factors[CONTROLLER_FACTOR] = controller_arm(scenario)
    return scenario, factors


def controller_arm(scenario: Scenario) -> str:
    """The run's arm in a campaign's summary: its controller, with " online"
    where the references come from the online estimates (``stiffness_source``
    online: the map-free controller) and " no watchdog" where the force
    sensor's watchdog is off, so that a campaign comparing them summarises
    them apart."""
    name = scenario.controller.reference.controller
    if scenario.stiffness_source == "online":
        name += " online"
    return name if scenario.watchdog.enabled else f"{name} no watchdog"


def plan_run(spec: CampaignSpec, base: Scenario, index: int) -> RunPlan:
    """The plan of run ``index`` (its scenario built and checked)."""
    _, factors = run_scenario(spec, base, index)
    return RunPlan(
        run_id=f"run_{index:05d}",
        index=index,
        factors=factors,
        spec=spec,
        base_yaml=dumps_scenario(base),
    )


def plan_campaign(spec: CampaignSpec, base: Scenario) -> list[RunPlan]:
    """Every run of the campaign, each scenario checked (before any run starts)."""
    base_yaml = dumps_scenario(base)
    plans = []
    for i in range(spec.runs):
        _, factors = run_scenario(spec, base, i)
        plans.append(RunPlan(f"run_{i:05d}", i, factors, spec, base_yaml))
    return plans


__all__ = [
    "CONTROLLERS",
    "RunPlan",
    "apply_controller",
    "controller_arm",
    "plan_campaign",
    "plan_run",
    "set_field",
]
