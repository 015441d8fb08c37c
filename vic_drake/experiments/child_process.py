"""A call in a Python process of its own: :func:`run_in_child`.

A Diagram with Python LeafSystems is never freed in pydrake (its systems'
bound methods keep them alive), so a process that built one Diagram per
scan would grow by what each scan's systems hold (about 100 MB a scan on
the synthetic chest: docs/decisions.md, "One process per campaign run").
A child's memory goes back to the system when it exits, and a crash of the
simulation (a signal, not an exception) costs that call only.

``python -m`` this module reads a pickled ``(function, args)`` on stdin,
calls it and writes the pickled result on stdout.
"""

import pickle
import signal
import subprocess
import sys

from vic_drake.malloc_tuning import tuned_environment


class ChildFailed(Exception):
    """The child process ended without a result; the message says why (its
    exit status and the last lines of its stderr)."""


def run_in_child(function, *args):
    """``function(*args)`` in a fresh Python process started with the scans'
    allocator (:func:`vic_drake.malloc_tuning.tuned_environment`).

    ``function`` must be importable by name (a module's top-level function)
    and ``args`` and the result must pickle.

    Raises:
        ValueError: ``VIC_DRAKE_ALLOCATOR`` is wrong on this machine.
        ChildFailed: the process exited without a readable result (an
            exception in ``function``, a crash, a signal).
    """
    env = tuned_environment()
    proc = subprocess.run(
        [sys.executable, "-m", "vic_drake.experiments.child_process"],
        input=pickle.dumps((function, args)),
        capture_output=True,
        check=False,
        env=env,
    )
    if proc.returncode == 0:
        try:
            return pickle.loads(proc.stdout)
        except Exception as exc:  # noqa: BLE001 - reported as the call's failure.
            reason = f"unreadable result ({type(exc).__name__}: {exc})"
    else:
        reason = f"its process exited with status {proc.returncode}"
    tail = proc.stderr.decode(errors="replace").strip().splitlines()[-3:]
    raise ChildFailed(reason + (": " + " | ".join(tail) if tail else ""))


def main() -> None:
    # A local worker starts with Ctrl-C blocked (the engine holds it back
    # while the cluster starts) and passes the mask on; a run's own process
    # takes Ctrl-C again, so that it stops a run at once.
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    function, args = pickle.load(sys.stdin.buffer)
    result = function(*args)
    sys.stdout.buffer.write(pickle.dumps(result))
    sys.stdout.flush()


if __name__ == "__main__":
    main()
