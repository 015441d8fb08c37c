"""Helpers shared by the subcommands: options, JSON output, progress."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.paths import DATA_ENV_VAR


def add_data_dir_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--data-dir",
        default=None,
        metavar="DIR",
        help=f"the paper's measurements (default: ${DATA_ENV_VAR}, else ../shared/data "
        "beside the project)",
    )


def add_json_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--json", action="store_true", help="print only the result as JSON on stdout"
    )


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.floating, float)):
        value = float(value)
        return value if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, Path):
        return str(value)
    return value


def to_json(result: dict) -> str:
    """JSON text of a result dict (numpy scalars converted, NaN/inf -> null)."""
    return json.dumps(_jsonable(result), indent=2, allow_nan=False)


def emit(result: dict, as_json: bool, human: str | None = None) -> None:
    """Prints the result: JSON alone on stdout, or a human summary."""
    if as_json:
        print(to_json(result))
    else:
        print(human if human is not None else to_json(result))


class Progress:
    """Progress lines on stderr (so ``--json`` keeps stdout to the JSON alone)."""

    def __init__(self, enabled: bool = True):
        self.enabled = enabled

    def __call__(self, message: str) -> None:
        if self.enabled:
            print(f"[vic-drake] {message}", file=sys.stderr, flush=True)


def parse_float_list(text: str, option: str) -> list[float]:
    """Parses '1.1,1.35' into floats, or raises VicDrakeError naming the option."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise VicDrakeError(
            f"{option} takes comma-separated numbers like 1.1,1.35,1.5; got {text!r}"
        ) from None
    if not values:
        raise VicDrakeError(f"{option} needs at least one number; got {text!r}")
    return values
