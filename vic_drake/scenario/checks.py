"""Field checks of the scenario configs: each names the field and the bad value."""

import math

from vic_drake.errors import VicDrakeError


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
