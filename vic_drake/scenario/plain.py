"""The plain form of a config tree (dicts, lists, scalars): equality and diffs.

Drake's bound config structs (``SimulatorConfig``, ``MultibodyPlantConfig``)
have no ``==``, and a sequence may be held as a tuple in code but loads as a
list from YAML. Comparing plain forms gives the equality a scenario needs
(``load(dump(s)) == s``) and :func:`differences` names every field where two
trees disagree.
"""

import dataclasses
import math

import numpy as np


def _record_fields(value) -> list[str] | None:
    """Field names of a dataclass instance or a Drake-bound config, else None."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return [f.name for f in dataclasses.fields(value)]
    fields = getattr(type(value), "__fields__", None)  # DefAttributesUsingSerialize.
    if fields is not None:
        return [f.name for f in fields]
    return None


def _attribute(value, name: str):
    # Bound types may store a YAML field under another attribute name
    # (the protocol of pydrake.common.yaml.yaml_dump_typed).
    if hasattr(value, "_rewrite_yaml_dump_attr_name"):
        name = value._rewrite_yaml_dump_attr_name(name)
    return getattr(value, name)


def as_plain(value):
    """The value as nested dicts (records), lists (sequences) and scalars."""
    names = _record_fields(value)
    if names is not None:
        return {name: as_plain(_attribute(value, name)) for name in names}
    if isinstance(value, dict):
        return {key: as_plain(item) for key, item in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [as_plain(item) for item in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _same_scalar(a, b, rtol: float, atol: float) -> bool:
    if a == b:
        return True
    numbers = (int, float)
    if (
        isinstance(a, numbers)
        and isinstance(b, numbers)
        and not isinstance(a, bool)
        and not isinstance(b, bool)
    ):
        if math.isnan(a) and math.isnan(b):
            return True
        return math.isclose(a, b, rel_tol=rtol, abs_tol=atol)
    return False


def _walk(a, b, path: str, rtol: float, atol: float, out: list[str]) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in list(a) + [k for k in b if k not in a]:
            sub = f"{path}.{key}" if path else str(key)
            if key not in a:
                out.append(f"{sub}: missing in the first, {b[key]!r} in the second")
            elif key not in b:
                out.append(f"{sub}: {a[key]!r} in the first, missing in the second")
            else:
                _walk(a[key], b[key], sub, rtol, atol, out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} items in the first, {len(b)} in the second")
            return
        for i, (x, y) in enumerate(zip(a, b)):
            _walk(x, y, f"{path}[{i}]", rtol, atol, out)
    elif not _same_scalar(a, b, rtol, atol):
        out.append(f"{path or '<root>'}: {a!r} in the first, {b!r} in the second")


def differences(first, second, *, rtol: float = 0.0, atol: float = 0.0) -> list[str]:
    """Every field where two config trees disagree, one line each.

    Args:
        first, second: config trees (dataclasses, Drake configs, lists, ...).
        rtol, atol: numbers closer than ``max(rtol * max(|a|, |b|), atol)``
            agree (``math.isclose``).

    Returns:
        Lines "field.path[i]: <first> in the first, <second> in the second";
        empty when the trees agree.
    """
    out: list[str] = []
    _walk(as_plain(first), as_plain(second), "", rtol, atol, out)
    return out
