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
import os
import sys

from vic_drake import __version__
from vic_drake.errors import VicDrakeError
from vic_drake.malloc_tuning import reexec_tuned
from vic_drake.paths import check_data_dir

# Modules under vic_drake.commands, each with register(subparsers).
COMMAND_MODULES = (
    "offline",
    "relaxation",
    "mapping",
    "control",
    "scans",
    "reproduce",
    "online",
    "campaign",
)


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
    if argv is None:
        # Run as the program: restart once with the scan processes' allocator
        # (vic_drake.malloc_tuning; same results, less allocator work).
        try:
            reexec_tuned()
        except ValueError as exc:
            print(f"vic-drake: error: {exc}", file=sys.stderr)
            return 2
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        # --data-dir or $VIC_DRAKE_DATA naming a folder without the data is
        # one error for every command, before any work.
        check_data_dir(getattr(args, "data_dir", None))
        return int(args.handler(args) or 0)
    except VicDrakeError as exc:
        print(f"vic-drake: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("vic-drake: interrupted", file=sys.stderr)
        if argv is None:
            # Run as the program: leave now. The run's files are closed, its
            # worker processes stopped; the interpreter's teardown of pydrake
            # would add 1-2 s (docs/decisions.md, "Output paths, data folder, Ctrl-C, run marker").
            # multiprocessing's own exit step first, so its semaphores are
            # released (else its resource tracker warns about leaks).
            import multiprocessing.util

            multiprocessing.util._exit_function()
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(130)
        return 130


if __name__ == "__main__":
    sys.exit(main())
