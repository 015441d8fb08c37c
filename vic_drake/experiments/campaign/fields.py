"""How a factor's value reaches a scenario: one field set, or a controller.

The planner (:mod:`.plan`) builds each run's scenario with these, and the
spec's check (:func:`.spec.load_campaign_spec`) sets each factor's extremes
with the same calls, so both see the same coercions and the same errors.
"""

from __future__ import annotations

import copy
import re
from dataclasses import fields, is_dataclass

from vic_drake.errors import VicDrakeError, field_hint
from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.paper import CONTROLLERS
from vic_drake.scenario import Scenario

_INDEXED = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\[(\d+)\]$")

#: The labels of a true/false field's factor (strings: quoted in YAML).
BOOL_LABELS = {"true": True, "false": False}


def _slot(scenario: Scenario, path: str) -> tuple[object, str, int | None]:
    """Where a dotted field path (``a.b[2].c``) ends: (the object holding
    it, the field's name, the item's index or None).

    Raises:
        VicDrakeError: an unknown field (with the fields there and the close
            names) or item.
    """
    obj = scenario
    parts = path.split(".")
    for k, part in enumerate(parts):
        m = _INDEXED.match(part)
        name, index = (m.group(1), int(m.group(2))) if m else (part, None)
        names = [f.name for f in fields(obj)] if is_dataclass(obj) else []
        if name not in names:
            where = ".".join(parts[:k]) or "the scenario"
            raise VicDrakeError(
                f"factor {path!r}: {where} has no field {name!r}"
                + field_hint(name, names)
            )
        if index is not None:
            seq = getattr(obj, name)
            if not isinstance(seq, list) or index >= len(seq):
                raise VicDrakeError(f"factor {path!r}: {name} has no item {index}")
        if k == len(parts) - 1:
            return obj, name, index
        obj = getattr(obj, name) if index is None else getattr(obj, name)[index]
    raise VicDrakeError(f"factor {path!r}: an empty field path")


def field_value(scenario: Scenario, path: str):
    """The value a dotted field path holds (VicDrakeError: unknown field)."""
    obj, name, index = _slot(scenario, path)
    value = getattr(obj, name)
    return value if index is None else value[index]


def set_field(scenario: Scenario, path: str, value) -> None:
    """Sets a dotted field path (``a.b[2].c``) of a scenario, type-checked.

    Raises:
        VicDrakeError: an unknown field, or a value of the wrong kind.
    """
    obj, name, index = _slot(scenario, path)
    if index is None:
        setattr(obj, name, _coerce(path, getattr(obj, name), value))
    else:
        seq = getattr(obj, name)
        seq[index] = _coerce(path, seq[index], value)


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


__all__ = ["BOOL_LABELS", "CONTROLLERS", "apply_controller", "set_field"]
