"""Ctrl-C held back over a step (vic_drake.ctrl_c), and the command line's
reading of an import that Ctrl-C cut (vic_drake.cli)."""

import os
import signal
import threading

import pytest

from vic_drake.cli import _interrupted_import
from vic_drake.ctrl_c import hold_ctrl_c, release_ctrl_c

needs_masks = pytest.mark.skipif(
    not hasattr(signal, "pthread_sigmask"), reason="no signal masks here"
)


@needs_masks
def test_a_held_ctrl_c_waits_for_the_release():
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signals reach the main thread only")
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        held = hold_ctrl_c()
        os.kill(os.getpid(), signal.SIGINT)  # Held: no KeyboardInterrupt yet.
        with pytest.raises(KeyboardInterrupt):
            release_ctrl_c(held)
        assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())
    finally:
        signal.signal(signal.SIGINT, previous)


def _import_error_from(cause):
    try:
        try:
            raise cause
        except BaseException as exc:
            raise ImportError("initialization failed") from exc
    except ImportError as exc:
        return exc


@pytest.mark.parametrize(
    "cause, interrupted",
    [(KeyboardInterrupt(), True), (ValueError("bad"), False), (None, False)],
)
def test_an_import_cut_by_ctrl_c_is_an_interrupt(cause, interrupted):
    exc = ImportError("no module") if cause is None else _import_error_from(cause)
    assert _interrupted_import(exc) is interrupted
