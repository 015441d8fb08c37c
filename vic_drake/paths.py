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

from vic_drake.errors import DataNotFoundError, VicDrakeError

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


_DATA_LAYOUT = "phantom_map/, experiments/, palpation/ and loadcycle/"


def check_data_dir(data_dir: str | os.PathLike | None = None) -> None:
    """Fails when the user named a data folder that does not hold the data.

    A folder given as ``--data-dir`` or in ``$VIC_DRAKE_DATA`` must hold the
    paper's measurements (both are the same error); only the default
    ``../shared/data`` may be absent (the run then uses the synthetic phantom).

    Raises:
        DataNotFoundError: naming the option or variable, the path and the
            expected layout.
    """
    if data_dir is not None:
        source, hint = f"--data-dir {str(data_dir)!r}", "omit the option"
    elif os.environ.get(DATA_ENV_VAR):
        source = f"{DATA_ENV_VAR}={os.environ[DATA_ENV_VAR]!r}"
        hint = f"unset {DATA_ENV_VAR}"
    else:
        return
    path = resolve_data_dir(data_dir)
    if not has_data(path):
        what = (
            "does not exist" if not path.exists() else "does not hold the paper's data"
        )
        raise DataNotFoundError(
            f"{source}: {str(path)!r} {what}; expected {_DATA_LAYOUT} in it ({hint} "
            "to run on the synthetic phantom)"
        )


def find_data_dir(data_dir: str | os.PathLike | None = None) -> Path | None:
    """The data folder to use, or None where there is none (synthetic phantom).

    Raises:
        DataNotFoundError: ``--data-dir`` or ``$VIC_DRAKE_DATA`` names a folder
            without the data (:func:`check_data_dir`).
    """
    check_data_dir(data_dir)
    path = resolve_data_dir(data_dir)
    return path if has_data(path) else None


def require_data_dir(data_dir: str | os.PathLike | None = None) -> Path:
    """Returns the data folder, or raises DataNotFoundError naming where it looked."""
    path = resolve_data_dir(data_dir)
    if not path.is_dir():
        raise DataNotFoundError(
            f"data folder {str(path)!r} does not exist; pass --data-dir DIR or set "
            f"{DATA_ENV_VAR} to the folder holding {_DATA_LAYOUT}"
        )
    return path


#: Figure files the commands' --plot can write (matplotlib's formats).
PLOT_SUFFIXES = (
    ".png",
    ".pdf",
    ".svg",
    ".jpg",
    ".jpeg",
    ".eps",
    ".ps",
    ".tif",
    ".tiff",
)


def _first_existing_parent(path: Path) -> Path:
    p = path
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def check_output_dir(path: str | os.PathLike, option: str = "--out") -> Path:
    """Checks, before any work, that ``path`` can be a folder we write into.

    Creates it (and its parents) and writes and removes a probe file.

    Raises:
        VicDrakeError: it is a file, or cannot be created or written.
    """
    out = Path(path).expanduser()
    if out.exists() and not out.is_dir():
        raise VicDrakeError(
            f"{option} {str(out)!r} is a file; give a folder (it is created)"
        )
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".vic-drake-write-test-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise VicDrakeError(
            f"{option} {str(out)!r} cannot be written: {exc.strerror or exc} "
            f"(check {str(_first_existing_parent(out))!r}); give a folder you can "
            "write to"
        ) from None
    return out


def check_output_file(
    path: str | os.PathLike,
    option: str,
    suffixes: tuple[str, ...] | None = None,
) -> Path:
    """Checks, before any work, that a file can be written at ``path``.

    Creates the parent folder, and checks the suffix (when ``suffixes`` is
    given), that ``path`` is not a folder, and that the folder is writable.

    Raises:
        VicDrakeError: naming the option, the path and what is allowed.
    """
    out = Path(path).expanduser()
    if suffixes is not None and out.suffix.lower() not in suffixes:
        raise VicDrakeError(
            f"{option} must end in {' or '.join(suffixes)}; got {str(out)!r}"
        )
    if out.is_dir():
        raise VicDrakeError(f"{option} {str(out)!r} is a folder; give a file name")
    check_output_dir(out.parent, option=f"{option}'s folder")
    if out.exists() and not os.access(out, os.W_OK):
        raise VicDrakeError(f"{option} {str(out)!r} exists and cannot be overwritten")
    return out
