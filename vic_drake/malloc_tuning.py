"""glibc malloc settings for the processes that simulate scans.

Every plant step of a scan allocates and frees many small heap blocks (Drake's
SAP solver builds a model and two contexts per step; pybind11 and numpy
temporaries), more than glibc's per-thread cache keeps per block size, so
most of them take glibc's slower paths. :data:`TUNABLES` enlarges that
cache. Allocation does not enter the arithmetic: the results are the same
bits. See docs/decisions.md, "glibc's malloc cache".

glibc reads ``GLIBC_TUNABLES`` once, when a process starts, so the setting
goes into the environment of a new process: :func:`reexec_tuned` restarts
the running program with it (``vic-drake`` does, before any work), and
:func:`tuned_environment` gives the environment to start another process
with (the campaign's worker processes). A ``GLIBC_TUNABLES`` that already
sets one of these tunables keeps its value: e.g.
``GLIBC_TUNABLES=glibc.malloc.tcache_count=7`` runs with glibc's default.
"""

from __future__ import annotations

import os
import sys

#: The environment variable glibc reads its tunables from.
ENV_VAR = "GLIBC_TUNABLES"

#: (tunable, value): cached freed blocks per size class (glibc's maximum;
#: the default is 7).
TUNABLES = (("glibc.malloc.tcache_count", "65535"),)


def uses_glibc() -> bool:
    """Whether this process runs on glibc (the only C library these settings mean anything to)."""
    try:
        return os.confstr("CS_GNU_LIBC_VERSION").startswith("glibc")
    except (AttributeError, ValueError, OSError):
        return False


def tuned_tunables(current: str | None) -> str:
    """The ``GLIBC_TUNABLES`` value: ``current`` plus :data:`TUNABLES`.

    A tunable that ``current`` already sets keeps its value; the order of
    ``current``'s entries is kept.
    """
    entries = [entry for entry in (current or "").split(":") if entry]
    named = {entry.split("=", 1)[0] for entry in entries}
    entries += [f"{name}={value}" for name, value in TUNABLES if name not in named]
    return ":".join(entries)


def is_tuned(environ=None) -> bool:
    """Whether ``environ`` (default: this process's) already names every tunable."""
    env = os.environ if environ is None else environ
    current = env.get(ENV_VAR, "")
    return tuned_tunables(current) == current


def tuned_environment(environ=None) -> dict[str, str]:
    """A copy of ``environ`` (default: this process's) with the tuned ``GLIBC_TUNABLES``."""
    env = dict(os.environ if environ is None else environ)
    env[ENV_VAR] = tuned_tunables(env.get(ENV_VAR))
    return env


def reexec_tuned() -> None:
    """Restarts this program (same interpreter and arguments) with the tuned environment.

    Does nothing when the environment is already tuned (so it restarts at
    most once) or the C library is not glibc. Call it before any output.
    """
    if is_tuned() or not uses_glibc():
        return
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(sys.executable, list(sys.orig_argv), tuned_environment())


__all__ = [
    "ENV_VAR",
    "TUNABLES",
    "is_tuned",
    "reexec_tuned",
    "tuned_environment",
    "tuned_tunables",
    "uses_glibc",
]
