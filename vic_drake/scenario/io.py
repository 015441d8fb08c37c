"""Scenario YAML: load with Drake's ``yaml_load_typed``, dump with ``yaml_dump_typed``.

The loader fills a default :class:`~vic_drake.scenario.scenario.Scenario`
field by field from the real annotations of the config dataclasses; fields
missing from the file keep their defaults. ``__post_init__`` only ever saw
those defaults, so :meth:`Scenario.validate` runs on what was loaded. Errors
never surface as tracebacks: each is a :class:`VicDrakeError` naming the file
(or "scenario YAML"), the field path and the bad value. A YAML of another
kind that vic_drake writes or reads (a palpation campaign's settings, a
campaign spec) is named as such, by its top-level key (:data:`OTHER_FILES`).
"""

import dataclasses
import os
import types
import typing
from pathlib import Path

from pydrake.common.yaml import yaml_dump_typed, yaml_load, yaml_load_typed

from vic_drake.errors import VicDrakeError
from vic_drake.paths import check_input_file
from vic_drake.scenario.scenario import Scenario

#: Top-level keys of the other YAMLs of vic_drake -> what such a file is.
OTHER_FILES = {
    "campaign_params": (
        "a palpation campaign's settings, which vic-drake reproduce writes beside "
        "its palpation and map logs; a run's scan scenarios are its "
        "logs/nominal_*.yaml and logs/disturbance_*.yaml"
    ),
    "factors": "a campaign spec; run it with vic-drake campaign FILE --out DIR",
    "base_scenario": "a campaign spec; run it with vic-drake campaign FILE --out DIR",
}


def load_scenario(path: str | os.PathLike) -> Scenario:
    """Loads a scenario YAML with ``yaml_load_typed`` and validates it.

    Fields missing from the file keep their defaults; unknown fields, wrong
    types and invalid values raise.

    Raises:
        VicDrakeError: naming the file and the offending field and value.
    """
    if (
        isinstance(path, str)
        and not path.endswith((".yaml", ".yml"))
        and not (Path(path).exists())
    ):
        # A bare name such as "nominal_vs_vf_synthetic": the CLI takes it for
        # diagrams/NAME.yaml; from Python that is load_diagram's job.
        raise VicDrakeError(
            f"scenario file {path!r} does not exist; for a shipped scenario by "
            "name use vic_drake.experiments.load_diagram(name), or give the "
            "file's path (diagrams/NAME.yaml)"
        )
    path = check_input_file(path, "scenario file")
    return _load({"filename": str(path)}, f"scenario file {str(path)!r}")


def loads_scenario(text: str) -> Scenario:
    """Like :func:`load_scenario`, from YAML text."""
    if not isinstance(text, str) or not text.strip():
        raise VicDrakeError(
            f"scenario YAML: the text is empty ({text!r}); give the YAML of a "
            "Scenario (e.g. open(path).read()), or load_scenario(path) for a file"
        )
    return _load({"data": text}, "scenario YAML")


def _load(source: dict, where: str) -> Scenario:
    """yaml_load_typed on one source (``filename=`` or ``data=``), then validate."""
    scenario = load_typed(
        Scenario,
        source,
        where,
        schema_name="vic_drake.scenario.Scenario",
        other_files=OTHER_FILES,
    )
    try:
        return scenario.validate()
    except (VicDrakeError, TypeError, ValueError) as exc:
        raise VicDrakeError(f"{where}: {exc}") from None


def load_typed(
    schema: type,
    source: dict,
    where: str,
    *,
    schema_name: str,
    other_files: dict | None = None,
):
    """``yaml_load_typed`` of a config dataclass, its errors naming the field.

    Drake's loader reports some errors without the field (a wrong scalar:
    "invalid literal for int()") and unknown fields without the allowed
    ones; this names the field path, the bad value and, for an unknown
    field, the allowed names. Used for scenarios and campaign specs.

    Args:
        schema: the dataclass to load (its fields are filled from the file).
        source: ``{"filename": path}`` or ``{"data": text}``.
        where: what the messages start with, e.g. "scenario file 'x.yaml'".
        schema_name: the type named in the message, e.g.
            "vic_drake.scenario.Scenario".
        other_files: {top-level key: what a file with that key is} for the
            YAMLs of another kind that a user may give instead (e.g.
            :data:`OTHER_FILES` for scenarios).

    Raises:
        VicDrakeError: "{where}: {field and problem} (the fields and types
            are those of {schema_name})", or "{where}: not a ...: its
            top-level key ... marks ...".
    """
    try:
        return yaml_load_typed(schema=schema, **source)
    except VicDrakeError as exc:
        raise VicDrakeError(f"{where}: {exc}") from None
    except Exception as exc:
        # Drake's loader raises RuntimeError, ValueError or yaml errors.
        raise VicDrakeError(
            f"{where}: {_explain(source, exc, schema, schema_name, other_files)}"
        ) from None


def _explain(source: dict, exc: Exception, schema, schema_name, other_files) -> str:
    """What is wrong: another kind of file, or the field path of the error
    (the Drake loader reports it without one)."""
    try:
        raw = yaml_load(**source)
    except Exception:
        return str(exc)
    if isinstance(raw, dict):
        for key, kind in (other_files or {}).items():
            if key in raw:
                return f"not a scan scenario: its top-level key {key!r} marks {kind}"
    path = _first_bad_field(raw, schema, "")
    what = f"field {path}" if path else f"{type(exc).__name__}: {exc}"
    return f"{what} (the fields and types are those of {schema_name})"


def _record_types(tp) -> dict | None:
    """Field name -> annotation of a dataclass or a Drake-bound config type."""
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        return {f.name: f.type for f in dataclasses.fields(tp)}
    fields = getattr(tp, "__fields__", None)  # DefAttributesUsingSerialize.
    if isinstance(tp, type) and fields is not None:
        return {f.name: f.type for f in fields}
    return None


_SCALARS = {float: (int, float), int: (int,), str: (str,), bool: (bool,)}


def _allowed_values(tp, name: str) -> str:
    """A dataclass field's allowed values in words (its ``metadata["allowed"]``),
    or ""."""
    if not (dataclasses.is_dataclass(tp) and isinstance(tp, type)):
        return ""
    for f in dataclasses.fields(tp):
        if f.name == name:
            return str(f.metadata.get("allowed", ""))
    return ""


def _first_bad_field(value, tp, path: str) -> str | None:
    """Path and problem of the first value that does not fit annotation tp."""
    hints = _record_types(tp)
    if hints is not None:
        if not isinstance(value, dict):
            return f"{path or '<root>'} must be a mapping; got {value!r}"
        for key, item in value.items():
            sub = f"{path}.{key}".lstrip(".")
            if key not in hints:
                return f"{sub} is unknown; allowed: {sorted(hints)}"
            bad = _first_bad_field(item, hints[key], sub)
            if bad:
                allowed = _allowed_values(tp, key)
                return f"{bad}; allowed: {allowed}" if allowed else bad
        return None
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin in (typing.Union, types.UnionType):
        if value is None:
            return None
        return _first_bad_field(
            value, [a for a in args if a is not type(None)][0], path
        )
    if origin is list:
        if not isinstance(value, list):
            return f"{path} must be a list; got {value!r}"
        for i, item in enumerate(value):
            bad = _first_bad_field(
                item, args[0] if args else typing.Any, f"{path}[{i}]"
            )
            if bad:
                return bad
        return None
    if tp in _SCALARS:
        ok = isinstance(value, _SCALARS[tp]) and not (
            tp is not bool and isinstance(value, bool)
        )
        if not ok:
            article = "an" if tp is int else "a"
            return f"{path} must be {article} {tp.__name__}; got {value!r}"
    return None


def dumps_scenario(scenario: Scenario, *, only_changes: bool = False) -> str:
    """The scenario as YAML text (``yaml_dump_typed``), loadable by load_scenario.

    Args:
        scenario: what to write.
        only_changes: write only the fields that differ from ``Scenario()``
            (Drake's ``defaults=``), as the files in ``diagrams/`` do: short,
            and they follow improvements of the defaults. False (default)
            writes every field: the exact record of a run.
    """
    if not isinstance(scenario, Scenario):
        raise VicDrakeError(
            f"dumps_scenario needs a Scenario; got {type(scenario).__name__}"
        )
    defaults = Scenario() if only_changes else None
    return yaml_dump_typed(scenario, schema=Scenario, defaults=defaults)


def save_scenario(
    scenario: Scenario, path: str | os.PathLike, *, only_changes: bool = False
) -> Path:
    """Writes the scenario as YAML (see :func:`dumps_scenario`); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(dumps_scenario(scenario, only_changes=only_changes))
    return path
