"""Ctrl-C held back over a step that must not be cut in the middle.

:func:`hold_ctrl_c` blocks SIGINT in the calling thread; the threads it
starts and the processes they start inherit the block. The kernel gives a
SIGINT sent to the process to any thread that does not block it (a thread
started before the hold: an interpreter's, a pool's), and Python then runs
its handler in the main thread at once; so in the main thread the hold also
puts in a handler that only notes the SIGINT. A Ctrl-C that arrives
meanwhile waits either way, and :func:`release_ctrl_c` hands it to the
handler that was there before: Python's raises KeyboardInterrupt there,
after the step. Where the platform has no signal masks both are no-ops.
"""

from __future__ import annotations

import signal
import threading
from typing import NamedTuple


class _Held(NamedTuple):
    """What :func:`release_ctrl_c` restores, and whether a SIGINT came."""

    mask: set
    handler: object  # The main thread's SIGINT handler before (None: not replaced).
    taken: list


def hold_ctrl_c() -> _Held | None:
    """Holds Ctrl-C back in this thread (see the module docstring); returns
    what :func:`release_ctrl_c` needs (None without signal masks)."""
    if not hasattr(signal, "pthread_sigmask"):
        return None
    taken = []
    handler = None
    if threading.current_thread() is threading.main_thread():
        before = signal.getsignal(signal.SIGINT)
        if before is not None:  # (None: a handler not set from Python; kept.)
            handler = signal.signal(signal.SIGINT, lambda *_: taken.append(True))
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    return _Held(mask, handler, taken)


def release_ctrl_c(held: _Held | None) -> None:
    """Ends :func:`hold_ctrl_c`'s hold. A Ctrl-C held back goes to the
    handler that was there before: Python's raises KeyboardInterrupt here,
    in the main thread; one ignored before is ignored."""
    if held is None:
        return
    # A SIGINT pending for this thread is taken (noted) as the mask lifts.
    signal.pthread_sigmask(signal.SIG_SETMASK, held.mask)
    if held.handler is not None:
        signal.signal(signal.SIGINT, held.handler)
        if held.taken:
            signal.raise_signal(signal.SIGINT)


__all__ = ["hold_ctrl_c", "release_ctrl_c"]
