"""What every benchmark prints with its figures: the versions that produced them."""

from __future__ import annotations

import importlib.metadata
import os
import platform
import subprocess
import sys

import numpy as np


def versions() -> str:
    """Drake, Python and numpy versions and the core count, for a figure's header."""
    return (
        f"drake {importlib.metadata.version('drake')}, "
        f"python {platform.python_version()}, numpy {np.__version__}, "
        f"{os.cpu_count()} cores"
    )


#: This checkout (the folder holding benchmarks/ and vic_drake/).
HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def is_checkout(path) -> bool:
    """Whether ``path`` holds a vic_drake package (a checkout to compare with)."""
    return path is not None and os.path.isdir(os.path.join(path, "vic_drake"))


def run_in_checkout(tree: str, command: list[str]) -> subprocess.CompletedProcess:
    """Runs ``command`` with the vic_drake of ``tree`` first on the path; exits on failure."""
    env = dict(os.environ, PYTHONPATH=os.path.abspath(tree))
    done = subprocess.run(command, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"the run with {tree} failed:\n{done.stderr[-2000:]}")
    return done
