"""Helpers shared by the subcommands: options, JSON output, progress."""

from __future__ import annotations

import argparse
import math
import sys

from vic_drake.errors import VicDrakeError
from vic_drake.jsonio import to_json
from vic_drake.paths import DATA_ENV_VAR, WITHOUT_DATA_SYNTHETIC

#: What the bag-reading commands do without a data folder (check_data_dir).
WITHOUT_DATA_BAGS = "read bag paths only as given"


def add_data_dir_option(
    parser: argparse.ArgumentParser,
    without: str | None = WITHOUT_DATA_SYNTHETIC,
    *,
    bags: bool = False,
) -> None:
    """The one ``--data-dir DIR`` option (the data folder, paths.resolve_data_dir).

    Args:
        without: what the command does without a data folder (the bad-folder
            error's "omit the option to ..."; paths.check_data_dir); None
            when it needs the data.
        bags: the command reads bags, which are also looked up in the data
            folder (:func:`bag_path`).
    """
    text = (
        f"the paper's measurements (default: ${DATA_ENV_VAR}, else ../shared/data "
        "beside the project)"
    )
    if bags:
        text += "; a relative BAG_DIR that is not in the current folder is read from it"
    parser.add_argument("--data-dir", default=None, metavar="DIR", help=text)
    parser.set_defaults(without_data=without)


def add_bag_data_dir_option(parser: argparse.ArgumentParser) -> None:
    """``--data-dir`` of a command that reads bags (and needs nothing else there)."""
    add_data_dir_option(parser, WITHOUT_DATA_BAGS, bags=True)


def bag_path(args: argparse.Namespace, text: str, what: str = "bag", expected=None):
    """The bag ``text`` names: as given, else in the data folder (paths.find_bag).

    Raises:
        DataNotFoundError: naming where it looked and ``expected``.
    """
    from vic_drake.paths import find_bag

    kwargs = {} if expected is None else {"expected": expected}
    return find_bag(text, getattr(args, "data_dir", None), what=what, **kwargs)


def help_text(doc: str, paragraph: int | None = None) -> str:
    """A docstring (or one of its paragraphs) as --help text: reST's double
    backticks dropped (argparse prints them as they are)."""
    if paragraph is not None:
        doc = doc.split("\n\n")[paragraph]
    return doc.replace("``", "")


def fmt_number(value, spec: str = ".3f") -> str:
    """``value`` formatted with ``spec``, or "n/a" for None and non-finite values."""
    if value is None or not math.isfinite(float(value)):
        return "n/a"
    return format(value, spec)


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
            f"{option} takes comma-separated numbers like 1.5,1.35,1.1; got {text!r}"
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
