"""What every benchmark prints with its figures: the versions that produced them."""

from __future__ import annotations

import importlib.metadata
import os
import platform

import numpy as np


def versions() -> str:
    """Drake, Python and numpy versions and the core count, for a figure's header."""
    return (
        f"drake {importlib.metadata.version('drake')}, "
        f"python {platform.python_version()}, numpy {np.__version__}, "
        f"{os.cpu_count()} cores"
    )
