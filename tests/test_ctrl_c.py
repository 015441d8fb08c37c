"""Ctrl-C held back over a step (vic_drake.ctrl_c), and the command line's
reading of an import that Ctrl-C cut (vic_drake.cli)."""

import signal
import threading
import time

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
        # To this thread: a SIGINT sent to the process may reach another
        # thread later (the next test).
        signal.pthread_kill(threading.get_ident(), signal.SIGINT)
        with pytest.raises(KeyboardInterrupt):  # Held until here.
            release_ctrl_c(held)
        assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())
    finally:
        signal.signal(signal.SIGINT, previous)


@needs_masks
def test_a_ctrl_c_that_another_thread_receives_is_held_too():
    # The kernel gives a process's SIGINT to any thread that does not block
    # it (a thread started before the hold, e.g. a kernel's or a pool's);
    # before, Python then raised KeyboardInterrupt here at once.
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signals reach the main thread only")
    stop = threading.Event()
    other = threading.Thread(target=stop.wait, daemon=True)
    other.start()
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        for _ in range(5):
            held = hold_ctrl_c()
            # To the other thread (a SIGINT sent to the process goes there
            # too, whenever the kernel gets to it): it runs the C handler
            # when it next runs, and Python then runs the handler here. Wait
            # for that (white box: the hold's note), up to 5 s.
            signal.pthread_kill(other.ident, signal.SIGINT)
            deadline = time.monotonic() + 5.0
            while not held.taken and time.monotonic() < deadline:
                # A signal that another thread took does not wake this loop
                # (CPython 3.11 sets the eval breaker only from the main
                # thread); a pthread_sigmask call runs the pending handlers.
                time.sleep(0.001)
                signal.pthread_sigmask(signal.SIG_BLOCK, [])
            assert held.taken  # Noted, not raised.
            with pytest.raises(KeyboardInterrupt):
                release_ctrl_c(held)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, previous)
        stop.set()
        other.join()


@needs_masks
def test_a_held_ctrl_c_goes_to_the_handler_that_was_there():
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signals reach the main thread only")
    calls = []
    previous = signal.signal(signal.SIGINT, lambda *_: calls.append("handler"))
    try:
        held = hold_ctrl_c()
        signal.raise_signal(signal.SIGINT)
        assert calls == []
        release_ctrl_c(held)
        assert calls == ["handler"]
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        held = hold_ctrl_c()
        signal.raise_signal(signal.SIGINT)
        release_ctrl_c(held)  # Ignored before the hold: ignored after it.
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        release_ctrl_c(hold_ctrl_c())  # No Ctrl-C meanwhile: nothing happens.
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
