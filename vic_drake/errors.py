"""User-facing errors, and the field check that raises them.

Everything that is the user's input being wrong (a missing bag, a bad option,
an invalid scenario field) raises :class:`VicDrakeError` with a message that
names what is wrong and what is allowed. The command line prints the message
and exits with status 2 instead of a traceback.
"""

import math


class VicDrakeError(ValueError):
    """Bad input: the message names the offending item and what is allowed."""


class DataNotFoundError(VicDrakeError, FileNotFoundError):
    """The paper's measurements (or one file of them) are not where expected."""


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
