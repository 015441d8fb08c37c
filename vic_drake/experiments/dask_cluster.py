"""The Dask cluster that campaigns and sweeps run on, and Ctrl-C around it.

:func:`dask_client` connects to an existing scheduler by address or starts
a local cluster of worker processes; :func:`ctrl_c_stops_once` and
:func:`quiet_logs` let the first Ctrl-C stop the work and close the cluster
in order. Users: :mod:`vic_drake.experiments.campaign.engine` (campaigns),
:mod:`vic_drake.experiments.online_sweep` (the closed-loop comparison
over dither frequencies) and :mod:`vic_drake.experiments.palpation_campaign`
(the palpations behind ``vic-drake map``).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import threading
import time

from vic_drake.ctrl_c import hold_ctrl_c, release_ctrl_c
from vic_drake.errors import VicDrakeError
from vic_drake.malloc_tuning import allocator
from vic_drake.provenance import code_id


def dask_client(workers: int | None, scheduler: str | None):
    """(client, cluster): a client of the scheduler at ``scheduler``
    (cluster None), else of a new local cluster of ``workers`` worker
    processes (default: the machine's cores), one thread each, whose
    workers ignore Ctrl-C (:class:`~vic_drake.experiments.dask_workers.IgnoreCtrlC`).
    The caller closes both.

    Raises:
        VicDrakeError: the scheduler cannot be reached, or
            ``VIC_DRAKE_ALLOCATOR`` is wrong.
    """
    import dask
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except OSError as exc:
            raise VicDrakeError(
                f"cannot reach the Dask scheduler {scheduler!r}: {exc}"
            ) from None
    n = workers or os.cpu_count() or 1
    # The runs' own processes get the scans' allocator (execute_run_in_child);
    # the workers only dispatch. A bad VIC_DRAKE_ALLOCATOR fails here, first.
    try:
        allocator(os.environ)
    except ValueError as exc:
        raise VicDrakeError(str(exc)) from None
    from vic_drake.experiments.dask_workers import IgnoreCtrlC

    # Ctrl-C is held back while the cluster starts. Its threads and worker
    # processes inherit the blocked signal, so no worker stops half started
    # and prints its traceback. A Ctrl-C that came meanwhile is taken once
    # the workers ignore it (the mask restored: KeyboardInterrupt), and the
    # cluster is closed as after any Ctrl-C.
    if hasattr(signal, "pthread_sigmask"):
        # multiprocessing's resource tracker, started with the first worker
        # process, unblocks SIGINT in the thread that starts it: start it now.
        from multiprocessing import resource_tracker

        resource_tracker.ensure_running()
    held = hold_ctrl_c()
    cluster = client = None
    try:
        with dask.config.set({"distributed.scheduler.allowed-failures": 1}):
            cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # A free port: never clash with another.
                # A worker's own log is no news: a task's failure comes back
                # through its future, and a worker whose scheduler closes
                # first (Ctrl-C) would print a heartbeat traceback.
                silence_logs=logging.CRITICAL,
                env={"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"},
            )
        client = Client(cluster)
        client.register_plugin(IgnoreCtrlC())  # Ctrl-C stops the cluster in order.
        release_ctrl_c(held)
    except BaseException:
        with quiet_logs(True):
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()
        release_ctrl_c(held)
        raise
    return client, cluster


def check_scheduler(address: str) -> None:
    """Connects to the Dask scheduler at ``address`` and disconnects: a
    pipeline that uses it later fails at its start, not after its first
    stages.

    Raises:
        VicDrakeError: the scheduler cannot be reached (after 20 s).
    """
    client, _ = dask_client(None, address)
    client.close()


@contextlib.contextmanager
def ctrl_c_stops_once():
    """The first Ctrl-C raises KeyboardInterrupt; later ones are ignored.

    They would break the cluster's stop after the first, leaving its threads
    and processes behind: ``timeout -s INT`` sends two SIGINTs at once, an
    impatient user may press twice. Only in the main thread (the only one
    Python delivers signals to).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    state = {"raised": False}

    def handler(_signum, _frame):
        if not state["raised"]:
            state["raised"] = True
            raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextlib.contextmanager
def quiet_logs(quiet: bool):
    """While the cluster stops after Ctrl-C, Dask's and tornado's warnings
    about the cancelled runs and the lost workers are no news: hidden."""
    loggers = [logging.getLogger(n) for n in ("distributed", "tornado")]
    levels = [lg.level for lg in loggers]
    if quiet:
        for lg in loggers:
            lg.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for lg, level in zip(loggers, levels, strict=True):
            lg.setLevel(level)


def worker_status() -> tuple[str, str]:
    """(code_id, problem) of the process it runs in: what a Dask worker
    reports to :func:`check_workers` (problem "" when it can run scans)."""
    try:
        allocator(os.environ)
    except ValueError as exc:
        return code_id(), str(exc)
    return code_id(), ""


def check_workers(client) -> None:
    """Refuses a cluster whose workers cannot run this process's scans:
    other code (:func:`vic_drake.provenance.code_id`: vic_drake's source,
    Drake and Python), whose results would not be this code's, or a setting
    that fails every run at once (a bad ``VIC_DRAKE_ALLOCATOR``), which
    would drain the queue into error rows."""
    here = code_id()
    status = {}
    for addr in sorted(client.scheduler_info()["workers"]):
        try:  # A worker on an older vic_drake has no worker_status.
            status[addr] = tuple(client.run(worker_status, workers=[addr])[addr])
        except Exception as exc:  # Whatever it raised, it is not this code.
            name = type(exc).__name__
            status[addr] = (f"not this vic_drake (worker_status failed: {name})", "")
    broken = {a: p for a, (_, p) in status.items() if p}
    other = {a: c for a, (c, p) in status.items() if c != here and not p}
    if broken:
        shown = "; ".join(f"{a}: {p}" for a, p in sorted(broken.items())[:3])
        raise VicDrakeError(
            f"{len(broken)} Dask worker(s) cannot run scans: {shown}"
            + (f" (and {len(broken) - 3} more)" if len(broken) > 3 else "")
            + ". Every run given to them would fail: mend their environment"
        )
    if other:
        shown = "; ".join(f"{a}: {c}" for a, c in sorted(other.items())[:3])
        more = f" (and {len(other) - 3} more)" if len(other) > 3 else ""
        raise VicDrakeError(
            f"{len(other)} Dask worker(s) run other code than this process "
            f"({here}): {shown}{more}. Their results would not be this code's: "
            "install the same vic_drake, Drake and Python on the workers"
        )


@contextlib.contextmanager
def dask_session(workers: int | None, scheduler: str | None):
    """Yields ``(client, futures)``: a client of :func:`dask_client` and a
    dict for the caller's futures, once every worker is found to run this
    process's code and can run scans (:func:`check_workers`). On leaving (also on Ctrl-C, which
    :func:`ctrl_c_stops_once` turns into one KeyboardInterrupt) the futures
    are cancelled and the client and a local cluster closed, with Dask's
    warnings about the cancelled work hidden after Ctrl-C."""
    futures = {}
    interrupted = False
    with ctrl_c_stops_once():
        client, cluster = dask_client(workers, scheduler)
        try:
            check_workers(client)
            yield client, futures
        except KeyboardInterrupt:
            interrupted = True
            raise
        finally:
            with quiet_logs(interrupted):
                for fut in futures:
                    fut.cancel()
                if interrupted and cluster is not None:
                    _kill_local_workers(cluster)
                client.close()
                if cluster is not None:
                    cluster.close()


def _kill_local_workers(cluster) -> None:
    """Kills a local cluster's worker processes (after Ctrl-C).

    A worker busy in a task would be given about 2 s to end it before its
    nanny kills it; the task's result is dropped anyway (docs/decisions.md,
    "The reproduce scans on Dask").
    """
    for nanny in list(getattr(cluster, "workers", {}).values()):
        pid = getattr(getattr(nanny, "process", None), "pid", None)
        if pid:
            with contextlib.suppress(OSError):  # It has just ended.
                os.kill(pid, signal.SIGKILL)


def map_on_cluster(
    function, jobs, workers, scheduler, *, name: str, describe, on_done=None
) -> list:
    """``function(job)`` for each job on Dask (:func:`dask_session`), the
    results in the jobs' order.

    Args:
        function: a module-level function (a worker imports it).
        jobs: the jobs (plain data), or a callable that makes them from the
            number of the cluster's workers.
        name: the prefix of the tasks' keys.
        describe: ``describe(i)`` names job i in an error, e.g. "the scan
            true_map at 3 Hz".
        on_done: called as ``on_done(i, result, done)`` as each job ends
            (``done``: how many have); it may raise to stop the rest.

    Raises:
        VicDrakeError: the cluster cannot be had, or a job raised (named;
            the jobs still to run are cancelled).
        KeyboardInterrupt: on Ctrl-C, once the cluster is closed.
    """
    from distributed import as_completed

    with dask_session(workers, scheduler) as (client, futures):
        if callable(jobs):
            jobs = jobs(max(1, len(client.scheduler_info()["workers"])))
        stamp = time.time_ns()
        for i, job in enumerate(jobs):
            key = f"{name}-{i}-{stamp}"
            futures[client.submit(function, job, pure=False, key=key)] = i
        results = [None] * len(jobs)
        for done, fut in enumerate(as_completed(list(futures)), start=1):
            i = futures[fut]
            try:
                results[i] = fut.result()
            except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker.
                raise VicDrakeError(
                    f"{describe(i)} failed: {type(exc).__name__}: {exc}"
                ) from None
            if on_done is not None:
                on_done(i, results[i], done)
    return results


def _workers(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"takes an integer >= 1; got {text!r}")
    return n


def _address(text: str) -> str:
    if not text.strip():
        raise argparse.ArgumentTypeError("needs an address such as tcp://host:8786")
    return text


def add_cluster_arguments(
    parser: argparse.ArgumentParser,
    what: str,
    workers_note: str = "",
    *,
    in_process_default: bool = False,
) -> None:
    """``--workers N | --scheduler ADDRESS`` (one or the other): where
    ``what`` (e.g. "the campaign's runs") runs; ``workers_note`` ends the
    help of --workers. Both are checked as they are parsed.
    ``in_process_default``: --workers defaults to 1, which the caller runs in
    its own process (else None: the machine's cores)."""
    where = parser.add_mutually_exclusive_group()
    default = (
        "1: in this process, no cluster"
        if in_process_default
        else "the machine's cores"
    )
    where.add_argument(
        "--workers",
        type=_workers,
        default=1 if in_process_default else None,
        metavar="N",
        help=f"local Dask worker processes for {what} (default {default}"
        f"{workers_note})",
    )
    where.add_argument(
        "--scheduler",
        type=_address,
        default=None,
        metavar="ADDRESS",
        help=f"run {what} on an existing Dask scheduler, e.g. tcp://10.0.0.5:8786",
    )


__all__ = [
    "add_cluster_arguments",
    "check_scheduler",
    "check_workers",
    "ctrl_c_stops_once",
    "dask_client",
    "dask_session",
    "map_on_cluster",
    "quiet_logs",
    "worker_status",
]
