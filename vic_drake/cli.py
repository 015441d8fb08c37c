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
import warnings

from vic_drake import __version__
from vic_drake.ctrl_c import hold_ctrl_c, release_ctrl_c
from vic_drake.errors import VicDrakeError, VicDrakeWarning
from vic_drake.malloc_tuning import reexec_tuned
from vic_drake.paths import WITHOUT_DATA_SYNTHETIC, check_data_dir

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
    parser.set_defaults(_subparsers=subparsers)
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(f"vic_drake.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"vic_drake.commands.{name}":
                continue  # Area not installed in this build.
            raise
        module.register(subparsers)
    return parser


def subcommand_parser(
    parser: argparse.ArgumentParser, name: str
) -> argparse.ArgumentParser:
    """The parser of subcommand ``name`` (of :func:`build_parser`'s parser)."""
    return parser.get_default("_subparsers").choices[name]


def _unknown_arguments(parser: argparse.ArgumentParser, args, extras) -> None:
    """Fails on arguments no option took, with the subcommand's usage and,
    for a misspelt option, the closest of its options (difflib)."""
    import difflib

    sub = subcommand_parser(parser, args.command)
    options = [o for a in sub._actions for o in a.option_strings]
    hints = []
    for extra in extras:
        if extra.startswith("-"):
            near = difflib.get_close_matches(extra.split("=", 1)[0], options, n=1)
            if near:
                hints.append(f"did you mean {near[0]}?")
    message = f"unrecognized arguments: {' '.join(extras)}"
    sub.error(f"{message} ({'; '.join(hints)})" if hints else message)


def _check_command_name(parser: argparse.ArgumentParser, argv: list[str]) -> None:
    """Fails on a misspelt command with the closest names (argparse alone
    lists every command)."""
    import difflib

    words = [a for a in argv if not a.startswith("-")]
    if not words:
        return
    names = list(parser.get_default("_subparsers").choices)
    if words[0] in names:
        return
    near = difflib.get_close_matches(words[0], names, n=2, cutoff=0.6)
    if near:
        parser.error(
            f"unknown command {words[0]!r} (did you mean {' or '.join(near)}?); "
            f"the commands: {', '.join(names)}"
        )


#: Arguments that print and exit without running a command.
_PRINT_ONLY = ("-h", "--help", "--version")


def _only_prints(argv: list[str]) -> bool:
    """Whether the command line asks for help or the version (before any "--")."""
    for arg in argv:
        if arg == "--":
            return False
        if arg in _PRINT_ONLY:
            return True
    return False


def main(argv: list[str] | None = None) -> int:
    if argv is None:
        # Run as the program: restart once with the scan processes' allocator
        # (vic_drake.malloc_tuning; same results, less allocator work).
        try:
            reexec_tuned()
        except ValueError as exc:
            # A bad allocator name stops every command, but help and the
            # version still print (with the error as a note first).
            if not _only_prints(sys.argv[1:]):
                print(f"vic-drake: error: {exc}", file=sys.stderr)
                return 2
            print(f"vic-drake: note: {exc} (commands will not run)", file=sys.stderr)
    try:
        # Ctrl-C is caught from here on: building the parser imports the
        # commands' modules (numpy, scipy), which takes most of a second.
        return _run(argv)
    except (KeyboardInterrupt, ImportError) as exc:
        if isinstance(exc, ImportError) and not _interrupted_import(exc):
            raise
        print("vic-drake: interrupted", file=sys.stderr)
        if argv is None:
            # Run as the program: leave now. The run's files are closed, its
            # worker processes stopped; the interpreter's teardown of pydrake
            # would add 1-2 s (docs/decisions.md, "Output paths, data folder, Ctrl-C, run marker").
            # multiprocessing's own exit step first, so its semaphores are
            # released (else its resource tracker warns about leaks). Its
            # log records from here on are no news (a worker process it
            # reaps, seen by a library's watcher thread): none is shown.
            import logging
            import multiprocessing.util

            logging.disable(logging.CRITICAL)
            multiprocessing.util._exit_function()
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(130)
        return 130


def _import_drake_core() -> None:
    """Imports pydrake's core with Ctrl-C held back (taken right after, as a
    KeyboardInterrupt). A Ctrl-C inside its initialisation makes Drake log a
    critical error with the Python stack before the ImportError; the other
    compiled modules only raise, which :func:`main` takes as an interrupt."""
    held = hold_ctrl_c()
    try:
        import pydrake.common  # noqa: F401 - the import is the point.
    finally:
        release_ctrl_c(held)


def _interrupted_import(exc: ImportError) -> bool:
    """Whether Ctrl-C caused this ImportError: a KeyboardInterrupt during a
    compiled module's initialisation (pydrake's) comes out as "ImportError:
    initialization failed" with the interrupt as its cause."""
    seen = set()
    cause = exc.__cause__ or exc.__context__
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, KeyboardInterrupt):
            return True
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return False


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """vic_drake's own warnings as one line, others as Python shows them."""
    if issubclass(category, VicDrakeWarning):
        print(f"vic-drake: warning: {message}", file=file or sys.stderr)
    else:
        _python_show_warning(message, category, filename, lineno, file, line)


_python_show_warning = warnings.showwarning


def _run(argv: list[str] | None) -> int:
    """Parses the command line and runs its command; errors as exit status 2."""
    warnings.showwarning = _show_warning
    parser = build_parser()
    _check_command_name(parser, sys.argv[1:] if argv is None else argv)
    args, extras = parser.parse_known_args(argv)
    if extras:
        _unknown_arguments(parser, args, extras)
    _import_drake_core()
    try:
        # --data-dir or $VIC_DRAKE_DATA naming a folder without the data is
        # one error for every command, before any work.
        check_data_dir(
            getattr(args, "data_dir", None),
            getattr(args, "without_data", WITHOUT_DATA_SYNTHETIC),
        )
        return int(args.handler(args) or 0)
    except VicDrakeError as exc:
        print(f"vic-drake: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
