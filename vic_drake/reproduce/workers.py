"""Worker processes of the reproduce stages that a Ctrl-C stops at once.

:func:`worker_pool` is a spawn-context ``ProcessPoolExecutor`` whose workers
ignore SIGINT (a Ctrl-C in a terminal reaches the whole process group; the
main process alone decides) and are terminated, not waited for, when the
block exits with an exception (KeyboardInterrupt included): queued jobs are
cancelled and running ones killed, so an interrupted run stops within a
second or two instead of finishing the scans in flight.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import signal
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor

#: Seconds to wait for a terminated worker before killing it.
TERMINATE_GRACE_S = 0.5


def _ignore_sigint() -> None:
    """Worker initializer: Ctrl-C is the main process's to handle."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """Cancels the queued jobs and terminates the pool's worker processes."""
    # The executor forgets its processes in shutdown(): take them first.
    processes = list((getattr(pool, "_processes", None) or {}).values())
    for p in processes:
        if p.is_alive():
            p.terminate()
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        p.join(TERMINATE_GRACE_S)
        if p.is_alive():
            p.kill()
            p.join(TERMINATE_GRACE_S)


@contextlib.contextmanager
def worker_pool(workers: int) -> Iterator[ProcessPoolExecutor]:
    """A process pool (spawn) that is torn down at once when the block fails.

    Args:
        workers: number of worker processes (>= 1).
    """
    pool = ProcessPoolExecutor(
        max_workers=max(1, int(workers)),
        mp_context=multiprocessing.get_context("spawn"),
        initializer=_ignore_sigint,
    )
    try:
        yield pool
    except BaseException:
        stop_pool(pool)
        raise
    pool.shutdown(wait=True)
