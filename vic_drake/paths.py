"""Where the paper's measurements live.

The real data is never copied into this repository. It is found, in order:

1. an explicit path (the ``--data-dir`` option of the command line),
2. the ``VIC_DRAKE_DATA`` environment variable,
3. ``../shared/data`` relative to the project root (the folder holding
   ``pyproject.toml``), the layout of the development checkout.
"""

from __future__ import annotations

import os
from pathlib import Path

from vic_drake.errors import DataNotFoundError

DATA_ENV_VAR = "VIC_DRAKE_DATA"
PROJECT_ROOT = Path(__file__).resolve().parents[1]
DEFAULT_DATA_DIR = PROJECT_ROOT.parent / "shared" / "data"
#: The scenario files of the paper's runs (the source of truth of reproduce).
DIAGRAMS_DIR = PROJECT_ROOT / "diagrams"


def resolve_data_dir(data_dir: str | os.PathLike | None = None) -> Path:
    """Returns the data folder to use (it may not exist; see require_data_dir)."""
    if data_dir is not None:
        return Path(data_dir).expanduser()
    env = os.environ.get(DATA_ENV_VAR)
    if env:
        return Path(env).expanduser()
    return DEFAULT_DATA_DIR


def has_data(data_dir: str | os.PathLike | None = None) -> bool:
    """True when the data folder exists and holds the phantom map."""
    return (resolve_data_dir(data_dir) / "phantom_map" / "z.txt").is_file()


def require_data_dir(data_dir: str | os.PathLike | None = None) -> Path:
    """Returns the data folder, or raises DataNotFoundError naming where it looked."""
    path = resolve_data_dir(data_dir)
    if not path.is_dir():
        raise DataNotFoundError(
            f"data folder {str(path)!r} does not exist; pass --data-dir DIR or set "
            f"{DATA_ENV_VAR} to the folder holding phantom_map/, experiments/, "
            "palpation/ and loadcycle/"
        )
    return path
