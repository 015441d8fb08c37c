"""Which code computed a result: a hash of vic_drake's own source, and the
versions of what it runs on.

A campaign's rows come from many processes, possibly on other machines (an
external Dask cluster) and over several sessions (``--resume``). Each row
carries the :func:`code_id` of the process that computed it, so rows of two
different codes are never mixed without a word.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.metadata
import platform
from pathlib import Path

#: The package whose source :func:`code_id` hashes.
PACKAGE_DIR = Path(__file__).resolve().parent

#: Hex digits of :func:`code_id`.
CODE_ID_DIGITS = 12


def source_hash(package_dir: Path = PACKAGE_DIR) -> str:
    """SHA-256 (first :data:`CODE_ID_DIGITS` hex digits) of every ``.py``
    file under ``package_dir``, by relative path and content.

    A change to any module, docstrings included, changes it; the file's
    time stamps and caches (``__pycache__``) do not.
    """
    digest = hashlib.sha256()
    files = sorted(
        p for p in Path(package_dir).rglob("*.py") if "__pycache__" not in p.parts
    )
    for path in files:
        digest.update(path.relative_to(package_dir).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()[:CODE_ID_DIGITS]


def _version(name: str) -> str:
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


@functools.cache
def code_id() -> str:
    """This process's code: "vic_drake <version> source <hash>, drake
    <version>, python <version>".

    Two processes with the same id simulate alike; computed once per process
    (about 10 ms).
    """
    from vic_drake import __version__

    return (
        f"vic_drake {__version__} source {source_hash()}, drake {_version('drake')}, "
        f"python {platform.python_version()}"
    )


__all__ = ["CODE_ID_DIGITS", "PACKAGE_DIR", "code_id", "source_hash"]
