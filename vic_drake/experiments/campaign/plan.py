"""The runs of a campaign: each run's sampled factors and its exact scenario.

Run i draws from ``numpy.random.default_rng([seed, i])`` only (with
``paired``, from ``[seed, its grid round, 1]``), so its factors do not
depend on the order runs finish in, on the number of workers, or on which
runs a resumed campaign still has to do.
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass, fields, is_dataclass

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign.spec import CONTROLLER_FACTOR, CampaignSpec
from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.scenario import Scenario, dumps_scenario, loads_scenario
from vic_drake.tissue.phantom.population import sample_patient

#: The four controllers a ``controller`` factor may choose.
CONTROLLERS = ("cs", "cf", "vs-cf", "vs-vf")

_INDEXED = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\[(\d+)\]$")


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


def set_field(scenario: Scenario, path: str, value) -> None:
    """Sets a dotted field path (``a.b[2].c``) of a scenario, type-checked.

    Raises:
        VicDrakeError: an unknown field, or a value of the wrong kind.
    """
    obj = scenario
    parts = path.split(".")
    for k, part in enumerate(parts):
        last = k == len(parts) - 1
        m = _INDEXED.match(part)
        name, index = (m.group(1), int(m.group(2))) if m else (part, None)
        if not (is_dataclass(obj) and name in {f.name for f in fields(obj)}):
            raise VicDrakeError(f"factor {path!r}: the scenario has no field {part!r}")
        if index is not None:
            seq = getattr(obj, name)
            if not isinstance(seq, list) or index >= len(seq):
                raise VicDrakeError(f"factor {path!r}: {name} has no item {index}")
            if last:
                seq[index] = _coerce(path, seq[index], value)
                return
            obj = seq[index]
        elif last:
            setattr(obj, name, _coerce(path, getattr(obj, name), value))
        else:
            obj = getattr(obj, name)


#: The labels of a true/false field's factor (strings: quoted in YAML).
BOOL_LABELS = {"true": True, "false": False}


def _coerce(path: str, current, value):
    """The value in the kind of the field it replaces."""
    if isinstance(current, bool):
        if value not in BOOL_LABELS:
            raise VicDrakeError(
                f"factor {path!r} is true/false: it takes the labels "
                f"{list(BOOL_LABELS)} (quoted in YAML); got {value!r}"
            )
        return BOOL_LABELS[value]
    if isinstance(current, str):
        if not isinstance(value, str):
            raise VicDrakeError(
                f"factor {path!r} takes labels (strings); got {value!r}"
            )
        return value
    if isinstance(value, str):
        raise VicDrakeError(f"factor {path!r} takes numbers; got {value!r}")
    if isinstance(current, int):
        return int(round(value))
    if isinstance(current, (float, type(None))):
        return float(value)
    raise VicDrakeError(f"factor {path!r}: a {type(current).__name__} cannot be varied")


def apply_controller(scenario: Scenario, name: str) -> None:
    """Gives the scenario the paper's controller and FDCC settings of ``name``."""
    if name not in CONTROLLERS:
        raise VicDrakeError(
            f"controller factor: {name!r} is not one of {list(CONTROLLERS)}"
        )
    ref = synthetic_scenario(name)
    scenario.controller = copy.deepcopy(ref.controller)
    scenario.fdcc = copy.deepcopy(ref.fdcc)


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
