"""Ctrl-C that the run always sees, even where a library swallows or wraps it.

A KeyboardInterrupt raised inside a callback that C++ or a worker pool calls
can come back as another exception (a failed stage) or not at all (a
destructor prints "Exception ignored" and goes on). :func:`sigint_watch`
records every SIGINT before raising the KeyboardInterrupt as usual, so the
pipeline can ask :func:`interrupted` and stop the run as interrupted.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

_state = {"interrupted": False}


def interrupted() -> bool:
    """True once a SIGINT has arrived inside :func:`sigint_watch`."""
    return _state["interrupted"]


def _on_sigint(signum, frame) -> None:
    _state["interrupted"] = True
    raise KeyboardInterrupt


@contextlib.contextmanager
def sigint_watch() -> Iterator[None]:
    """Records SIGINTs during the block (main thread only; else a no-op)."""
    _state["interrupted"] = False
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, _on_sigint)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
