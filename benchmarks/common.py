"""What every benchmark prints with its figures: the versions that produced them."""

from __future__ import annotations

import argparse
import glob
import importlib.metadata
import importlib.util
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np


def allocator_in_use() -> str:
    """The allocator this process runs with: mimalloc when it is mapped into the
    process, else the C library's (with glibc's tunables, when set)."""
    try:
        with open("/proc/self/maps") as maps:
            if "libmimalloc" in maps.read():
                return "mimalloc"
    except OSError:
        pass
    tunables = os.environ.get("GLIBC_TUNABLES")
    return f"glibc ({tunables})" if tunables else "glibc (defaults)"


def versions() -> str:
    """Drake, Python and numpy versions, the core count and the allocator, for a
    figure's header."""
    return (
        f"drake {importlib.metadata.version('drake')}, "
        f"python {platform.python_version()}, numpy {np.__version__}, "
        f"{os.cpu_count()} cores, allocator {allocator_in_use()}"
    )


#: This checkout (the folder holding benchmarks/ and vic_drake/).
HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def is_checkout(path) -> bool:
    """Whether ``path`` holds a vic_drake package (a checkout to compare with)."""
    return path is not None and os.path.isdir(os.path.join(path, "vic_drake"))


def checkout_environment(tree: str) -> dict[str, str]:
    """The environment ``tree``'s own processes run with: its vic_drake first on
    the path and, when the checkout has ``vic_drake/malloc_tuning.py``, its
    ``GLIBC_TUNABLES`` (what its ``vic-drake`` and campaign workers set), so a
    checkout is measured as it runs. The paper's data folder is the one this
    process reads (``VIC_DRAKE_DATA``, else the default beside this checkout):
    another checkout's default would be beside it, and the two would time
    different logs."""
    env = dict(os.environ, PYTHONPATH=os.path.abspath(tree))
    from vic_drake.paths import has_data, resolve_data_dir

    if has_data():
        env["VIC_DRAKE_DATA"] = str(resolve_data_dir())
    path = os.path.join(tree, "vic_drake", "malloc_tuning.py")
    if not os.path.isfile(path):
        return env
    # Loaded from the file: the module is plain Python (os, sys) and each
    # checkout has its own.
    spec = importlib.util.spec_from_file_location("_checkout_malloc_tuning", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.tuned_environment(env) if module.uses_glibc() else env


def run_as_vic_drake() -> None:
    """Restarts this benchmark with this checkout's environment
    (:func:`checkout_environment`: the allocator ``vic-drake`` and the campaign
    workers run with), so an in-process figure is the one a scan process
    gives. At most once; ``VIC_DRAKE_ALLOCATOR=glibc`` measures glibc's."""
    from vic_drake.malloc_tuning import restart_with

    restart_with(checkout_environment(HERE))


def run_in_checkout(tree: str, command: list[str]) -> subprocess.CompletedProcess:
    """Runs ``command`` in ``tree``'s environment (:func:`checkout_environment`); exits on failure."""
    env = checkout_environment(tree)
    done = subprocess.run(command, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"the run with {tree} failed:\n{done.stderr[-2000:]}")
    return done


def run_timed(tree: str, command: list[str], cwd=None) -> tuple[str, float, float]:
    """Runs ``command`` in ``tree``'s environment (:func:`checkout_environment`);
    exits on failure. Returns (its stdout, wall s, peak RSS MB): wait4's
    ru_maxrss, the largest of the command's and of every process below it
    that was waited for (a local Dask cluster's workers included)."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen(
            command, env=checkout_environment(tree), stdout=out, stderr=err, cwd=cwd
        )
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        out.seek(0)
        err.seek(0)
        if os.waitstatus_to_exitcode(status) != 0:
            sys.exit(f"the run with {tree} failed:\n{err.read().decode()[-2000:]}")
        return out.read().decode(), wall, usage.ru_maxrss / 1024


def run_sections(sections: dict, doc: str) -> None:
    """The command line of a benchmark made of named sections.

    ``--section NAME`` (repeatable; default: all, in order) and
    ``--data-dir DIR``; each section is called with the resolved data folder.
    """
    from vic_drake.paths import resolve_data_dir

    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--section", choices=tuple(sections), action="append")
    parser.add_argument("--data-dir", default=None)
    args = parser.parse_args()
    data_dir = resolve_data_dir(args.data_dir)
    print(versions())
    for name in args.section or sections:
        print(f"== {name}")
        sections[name](data_dir)


def check_callgrind_baseline(parser: argparse.ArgumentParser, baseline) -> None:
    """Ends the command with a usage error when valgrind is missing or
    ``baseline`` (if given) is not a checkout of vic_drake."""
    if shutil.which("valgrind") is None:
        parser.error("valgrind is not installed (Debian: apt-get install valgrind)")
    if baseline is not None and not is_checkout(baseline):
        parser.error(f"--baseline must be a checkout of vic_drake; got {baseline}")


def callgrind_in_checkout(
    tree: str, script: str, worker_args: list[str]
) -> tuple[int, dict[str, int]]:
    """Runs ``script --worker ...`` of checkout ``tree`` under callgrind.

    The worker switches the instrumentation on and off itself, dumps each
    measured part under a label (``callgrind_control -d LABEL``) and prints
    ``ticks N``. Returns (N, {label: instructions of its dump}); ends the
    command with the run's stderr when either is missing.
    """
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "callgrind.out")
        command = ["valgrind", "--tool=callgrind", "--instr-atstart=no"]
        command += [f"--callgrind-out-file={out}", sys.executable]
        command += [os.path.abspath(script), "--worker", *worker_args]
        done = run_in_checkout(tree, command)
        ticks = re.search(r"^ticks (\d+)", done.stdout, re.M)
        dumps = {}
        for path in glob.glob(out + ".*"):
            with open(path) as f:
                text = f.read()
            label = re.search(r"^desc: Trigger: .* (\S+)$", text, re.M)
            summary = re.search(r"^summary: (\d+)", text, re.M)
            if label and summary:
                dumps[label.group(1)] = int(summary.group(1))
        if ticks is None or not dumps:
            sys.exit(f"the run of {tree} failed:\n{done.stderr[-2000:]}")
        return int(ticks.group(1)), dumps


def comma_list(parser: argparse.ArgumentParser, option: str, text: str, kind=str):
    """The comma-separated values of ``option`` as ``kind`` (str, int,
    float); exits through ``parser.error`` naming the option and the bad
    value, or when there is none."""
    values = [v.strip() for v in text.split(",") if v.strip()]
    if not values:
        parser.error(f"{option}: give at least one value; got {text!r}")
    try:
        return [kind(v) for v in values]
    except ValueError:
        name = {int: "integers", float: "numbers"}.get(kind, "values")
        parser.error(f"{option} takes comma-separated {name}; got {text!r}")


def print_row(row: dict) -> None:
    """One result as ``key=value`` pairs on a line (floats to 3 decimals)."""
    cells = (
        f"{k}={v:.3f}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items()
    )
    print(" ".join(cells), flush=True)


def data_dir_with_log(parser, data_dir, log: str):
    """The data folder holding ``experiments/<log>``; exits with a message
    when there is no data or no such log (for the benchmarks that need the
    measured map and a shared log)."""
    from vic_drake.paths import has_data, resolve_data_dir

    if not has_data(data_dir):
        sys.exit("this benchmark needs the data (the measured map); see README")
    folder = resolve_data_dir(data_dir)
    if not (folder / "experiments" / log).is_dir():
        parser.error(f"--log: no log {log!r} in {folder / 'experiments'}")
    return folder
