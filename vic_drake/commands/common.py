"""Helpers shared by the subcommands: options, JSON output, progress."""

from __future__ import annotations

import argparse
import sys

from vic_drake.errors import VicDrakeError
from vic_drake.jsonio import to_json
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
