"""The memory allocator of the processes that simulate scans.

Every plant step of a scan allocates and frees many small heap blocks (Drake's
SAP solver builds a model and two contexts per step; pybind11 and numpy
temporaries). glibc's allocator takes its slow paths for most of them. Two
remedies, both chosen when a process starts:

- mimalloc (the ``cmeel-mimalloc`` wheel, a dependency on Linux), loaded
  ahead of the C library with ``LD_PRELOAD``: every ``malloc`` and ``new`` of
  the process goes to it;
- glibc's per-thread cache enlarged (:data:`TUNABLES` in ``GLIBC_TUNABLES``),
  which also serves where mimalloc is not installed or is turned off.

Allocation does not enter the arithmetic: the results are the same bits. See
docs/decisions.md, "glibc's malloc cache" and "mimalloc for the scan
processes".

The C library reads both variables only when a process starts, so the
setting goes into the environment of a new process: :func:`reexec_tuned`
restarts the running program with it (``vic-drake`` does, before any work;
the Python processes it starts inherit it), and :func:`tuned_environment`
gives the environment to start another process with (each campaign run's
process). It is never written into a running process's ``os.environ``:
programs that a Python session starts afterwards (a browser, for one:
Chromium does not run with mimalloc preloaded) keep their own allocator. A
user's own setting wins:

- a ``GLIBC_TUNABLES`` that already sets one of these tunables keeps its
  value (``glibc.malloc.tcache_count=7`` is glibc's default);
- a non-empty ``LD_PRELOAD`` is left as it is (no mimalloc added);
- ``VIC_DRAKE_ALLOCATOR=glibc`` keeps glibc's allocator (tunables only).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping

#: The environment variable glibc reads its tunables from.
ENV_VAR = "GLIBC_TUNABLES"

#: The environment variable the dynamic loader reads libraries to load first from.
PRELOAD_VAR = "LD_PRELOAD"

#: The environment variable choosing the allocator: "mimalloc" (the default
#: where the library is installed) or "glibc".
ALLOCATOR_VAR = "VIC_DRAKE_ALLOCATOR"

#: The values :data:`ALLOCATOR_VAR` may take.
ALLOCATORS = ("mimalloc", "glibc")

#: (tunable, value): cached freed blocks per size class (glibc's maximum;
#: the default is 7).
TUNABLES = (("glibc.malloc.tcache_count", "65535"),)

#: The wheel that ships mimalloc, and its shared library inside it.
MIMALLOC_DISTRIBUTION = "cmeel-mimalloc"
MIMALLOC_LIBRARY = "cmeel.prefix/lib/libmimalloc.so"


def uses_glibc() -> bool:
    """Whether this process runs on glibc (the only C library these settings mean anything to)."""
    try:
        return os.confstr("CS_GNU_LIBC_VERSION").startswith("glibc")
    except (AttributeError, ValueError, OSError):
        return False


def mimalloc_library() -> str | None:
    """The path of the installed mimalloc shared library, or None (not installed).

    Looked for as :data:`MIMALLOC_LIBRARY` under the entries of ``sys.path``,
    where pip puts the wheel's files (no ``importlib.metadata``: this runs
    before every command restarts, and that import alone costs ~25 ms).
    """
    for entry in sys.path:
        path = os.path.abspath(os.path.join(entry or ".", MIMALLOC_LIBRARY))
        if os.path.isfile(path):
            # LD_PRELOAD separates its entries with spaces and colons: such
            # a path cannot be named there.
            return None if any(c in path for c in " \t:") else path
    return None


def allocator(environ=None) -> str:
    """The allocator ``environ`` (default: this process's) asks for.

    Raises:
        ValueError: :data:`ALLOCATOR_VAR` names none of :data:`ALLOCATORS`.
    """
    env = os.environ if environ is None else environ
    name = env.get(ALLOCATOR_VAR, "").strip().lower() or ALLOCATORS[0]
    if name not in ALLOCATORS:
        raise ValueError(
            f"{ALLOCATOR_VAR}={env[ALLOCATOR_VAR]!r}: choose from {', '.join(ALLOCATORS)}"
        )
    return name


def tuned_tunables(current: str | None) -> str:
    """The ``GLIBC_TUNABLES`` value: ``current`` plus :data:`TUNABLES`.

    A tunable that ``current`` already sets keeps its value; the order of
    ``current``'s entries is kept.
    """
    entries = [entry for entry in (current or "").split(":") if entry]
    named = {entry.split("=", 1)[0] for entry in entries}
    entries += [f"{name}={value}" for name, value in TUNABLES if name not in named]
    return ":".join(entries)


def tuned_preload(environ=None, library: str | None = None) -> str | None:
    """The ``LD_PRELOAD`` value a scan process should start with.

    ``environ``'s own value when it is non-empty or when it asks for glibc's
    allocator (None when it has none); else ``library`` (default:
    :func:`mimalloc_library`), or None when mimalloc is not installed.
    """
    env = os.environ if environ is None else environ
    name = allocator(env)  # A bad name is an error whatever else is set.
    current = env.get(PRELOAD_VAR) or None
    if current is not None or name != "mimalloc":
        return current
    return library if library is not None else mimalloc_library()


def is_tuned(environ=None) -> bool:
    """Whether ``environ`` (default: this process's) already has the settings."""
    env = os.environ if environ is None else environ
    current = env.get(ENV_VAR, "")
    preload = tuned_preload(env)
    return tuned_tunables(current) == current and env.get(PRELOAD_VAR) == preload


def tuned_environment(environ=None) -> dict[str, str]:
    """A copy of ``environ`` (default: this process's) with the allocator settings."""
    env = dict(os.environ if environ is None else environ)
    env[ENV_VAR] = tuned_tunables(env.get(ENV_VAR))
    preload = tuned_preload(env)
    if preload is not None:
        env[PRELOAD_VAR] = preload
    return env


def restart_with(env: Mapping[str, str]) -> None:
    """Restarts this program (same interpreter and arguments) with ``env``
    unless its allocator settings are already this process's (so it restarts
    at most once). Call it before any output."""
    if all(env.get(n) == os.environ.get(n) for n in (ENV_VAR, PRELOAD_VAR)):
        return
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(sys.executable, list(sys.orig_argv), dict(env))


def reexec_tuned() -> None:
    """Restarts this program with the tuned environment (:func:`restart_with`).

    Does nothing when the environment is already tuned or the C library is
    not glibc.

    Raises:
        ValueError: :data:`ALLOCATOR_VAR` names an unknown allocator.
    """
    if uses_glibc():
        restart_with(tuned_environment())


__all__ = [
    "ALLOCATORS",
    "ALLOCATOR_VAR",
    "ENV_VAR",
    "MIMALLOC_DISTRIBUTION",
    "PRELOAD_VAR",
    "TUNABLES",
    "allocator",
    "is_tuned",
    "mimalloc_library",
    "reexec_tuned",
    "restart_with",
    "tuned_environment",
    "tuned_preload",
    "tuned_tunables",
    "uses_glibc",
]
