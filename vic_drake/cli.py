"""The ``vic-drake`` command line.

Each area registers its subcommands from its own module in
``vic_drake.commands`` (``register(subparsers)``), so the parser stays small
and each command's options live beside its code. Every handler returns a
process exit status; a :class:`vic_drake.errors.VicDrakeError` (bad input) is
printed as ``vic-drake: error: ...`` with exit status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from vic_drake import __version__
from vic_drake.errors import VicDrakeError

# Modules under vic_drake.commands, each with register(subparsers).
COMMAND_MODULES = ("offline", "mapping", "control", "scans", "reproduce")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="vic-drake",
        description="Passive variable impedance control for robotic ultrasonography, on Drake.",
    )
    parser.add_argument(
        "--version", action="version", version=f"vic-drake {__version__}"
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(f"vic_drake.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"vic_drake.commands.{name}":
                continue  # Area not installed in this build.
            raise
        module.register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args) or 0)
    except VicDrakeError as exc:
        print(f"vic-drake: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("vic-drake: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
