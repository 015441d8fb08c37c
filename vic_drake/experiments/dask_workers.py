"""What a local Dask worker runs at start (a Dask worker plugin), for the
campaigns and the comparison sweep (:mod:`vic_drake.experiments.dask_cluster`).

Imported only when a local cluster is made (it imports ``distributed``).
"""

from __future__ import annotations

import logging
import signal
import threading

from distributed.diagnostics.plugin import WorkerPlugin


def _ignore(_signum, _frame) -> None:
    """A SIGINT handler that does nothing (see :class:`IgnoreCtrlC`)."""


class IgnoreCtrlC(WorkerPlugin):
    """A local worker process ignores Ctrl-C; the campaign process stops it.

    Ctrl-C in a terminal reaches every process of the foreground group: the
    campaign, its worker processes and their runs' processes. A worker that
    stopped on it printed the tracebacks of its nanny and event loop; this
    one leaves its shutdown to the campaign, which closes the cluster in
    order. The handler is a Python function, not SIG_IGN: the runs' own
    processes (:func:`~vic_drake.experiments.child_process.run_in_child`)
    start with the default handler again, so Ctrl-C still stops a run at
    once.
    """

    name = "vic-drake-ignore-ctrl-c"

    def setup(self, worker) -> None:
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, _ignore)
        # Its one warning, "Async instruction ... ended with CancelledError",
        # comes only from a worker closed while it runs a task (distributed
        # 2026.8: "This should exclusively happen in Worker.close()"), as
        # after Ctrl-C; the campaign says itself which runs it kept.
        logging.getLogger("distributed.worker.state_machine").setLevel(logging.ERROR)


__all__ = ["IgnoreCtrlC"]
