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


def parse_relaxation(text: str, option: str = "--relaxation"):
    """``option`` G:TAU[,G:TAU...]: the relaxing law's branches (RelaxationParams)."""
    from vic_drake.tissue.relaxation import RelaxationParams

    usage = (
        f"{option} takes G:TAU pairs separated by commas (fraction g >= 0, "
        "the fractions summing to < 1; time constant tau > 0 s), e.g. "
        f"0.08:22.9,0.03:1.7; got {text!r}"
    )
    pairs = []
    for item in text.split(","):
        parts = item.split(":")
        try:
            g, tau = (float(v) for v in parts)
        except ValueError:
            raise VicDrakeError(usage) from None
        pairs.append((g, tau))
    try:
        return RelaxationParams(
            tuple(g for g, _ in pairs), tuple(tau for _, tau in pairs)
        )
    except VicDrakeError:
        raise VicDrakeError(usage) from None
