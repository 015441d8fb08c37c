"""Ctrl-C held back over a step that must not be cut in the middle.

:func:`hold_ctrl_c` blocks SIGINT in the calling thread; the threads it
starts and the processes they start inherit the block. A Ctrl-C that
arrives meanwhile waits, and :func:`release_ctrl_c` lets it through: Python
raises KeyboardInterrupt there, after the step. Where the platform has no
signal masks both are no-ops.
"""

from __future__ import annotations

import signal


def hold_ctrl_c():
    """Blocks SIGINT in this thread; returns the previous mask for
    :func:`release_ctrl_c` (None without signal masks)."""
    if not hasattr(signal, "pthread_sigmask"):
        return None
    return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})


def release_ctrl_c(held) -> None:
    """Restores the mask of :func:`hold_ctrl_c` (a Ctrl-C held back raises
    KeyboardInterrupt here, in the main thread)."""
    if held is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


__all__ = ["hold_ctrl_c", "release_ctrl_c"]
