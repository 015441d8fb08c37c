"""User-facing errors, and the field check that raises them.

Everything that is the user's input being wrong (a missing bag, a bad option,
an invalid scenario field) raises :class:`VicDrakeError` with a message that
names what is wrong and what is allowed. The command line prints the message
and exits with status 2 instead of a traceback.
"""

import dataclasses
import difflib
import math


class VicDrakeError(ValueError):
    """Bad input: the message names the offending item and what is allowed."""


class DataNotFoundError(VicDrakeError, FileNotFoundError):
    """The paper's measurements (or one file of them) are not where expected."""


class VicDrakeWarning(UserWarning):
    """Something a run does that its user may not expect, though it runs
    (the command line prints it as "vic-drake: warning: ...")."""


def check_number(
    owner: str, name: str, value, *, low=None, low_open=False, high=None
) -> float:
    """Checks one scalar field; returns it as float or raises naming it.

    Args:
        owner: the config class's name, as the message shows it.
        name: the field's name (or ``field[i]`` for an item).
        value: what the field holds.
        low: lower bound, inclusive unless ``low_open``; None for none.
        low_open: the lower bound is exclusive.
        high: upper bound, inclusive; None for none.

    Raises:
        VicDrakeError: "<owner>.<name> must be ...; got <value>".
    """
    # Text that reads as a number ("5") would pass float() and stay text in
    # the field, to fail deep in a simulation; true/false is no number.
    if isinstance(value, (str, bytes, bool)):
        raise VicDrakeError(
            f"{owner}.{name} must be a number; got {value!r} (a {type(value).__name__})"
        )
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise VicDrakeError(f"{owner}.{name} must be a number; got {value!r}") from None
    if not math.isfinite(v):
        raise VicDrakeError(f"{owner}.{name} must be finite; got {value!r}")
    if low is not None and (v <= low if low_open else v < low):
        op = ">" if low_open else ">="
        raise VicDrakeError(f"{owner}.{name} must be {op} {low}; got {value!r}")
    if high is not None and v > high:
        raise VicDrakeError(f"{owner}.{name} must be <= {high}; got {value!r}")
    return v


def field_hint(name: str, fields) -> str:
    """ "; did you mean a, b? Its fields: ..." for an unknown field ``name``
    among ``fields`` (the close names first, when there are any)."""
    fields = list(fields)
    near = difflib.get_close_matches(name, fields, n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(near)}?" if near else ""
    return hint + (f" Its fields: {', '.join(fields)}" if fields else "")


def check_known_attributes(obj, owner: str) -> None:
    """Refuses an attribute that is not a field, on a dataclass and on every
    dataclass in its fields (lists and dicts of them included).

    Python lets code set any attribute: ``params.force_ref = 5.0`` (for
    ``force_ref_N``) would be kept and never read. The YAML loader refuses
    such a key; this gives the same for a config changed in code.

    Raises:
        VicDrakeError: "<owner>.<path> has no field 'x'; did you mean ...".
    """
    if not dataclasses.is_dataclass(obj) or isinstance(obj, type):
        return
    fields = [f.name for f in dataclasses.fields(obj)]
    for name in getattr(obj, "__dict__", {}):
        if name not in fields and not name.startswith("_"):
            raise VicDrakeError(
                f"{owner} has no field {name!r} (set in code, it would be "
                f"ignored){field_hint(name, fields)}"
            )
    for name in fields:
        value = getattr(obj, name)
        items = (
            value.items()
            if isinstance(value, dict)
            else enumerate(value)
            if isinstance(value, (list, tuple))
            else ()
        )
        check_known_attributes(value, f"{owner}.{name}")
        for key, item in items:
            check_known_attributes(item, f"{owner}.{name}[{key!r}]")
