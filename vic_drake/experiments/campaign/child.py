"""A campaign run in a process of its own: ``python -m`` this module.

Reads a pickled :class:`~vic_drake.experiments.campaign.plan.RunPlan` on
stdin, runs :func:`~vic_drake.experiments.campaign.run.execute_run` and
writes the pickled row on stdout. See :func:`execute_run_in_child` for why
a run gets its own process.
"""

import pickle
import signal
import sys

from vic_drake.experiments.campaign.run import execute_run


def main() -> None:
    # A local worker starts with Ctrl-C blocked (the engine holds it back
    # while the cluster starts) and passes the mask on; a run's own process
    # takes Ctrl-C again, so that it stops a run at once.
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    plan = pickle.load(sys.stdin.buffer)
    row = execute_run(plan)
    sys.stdout.buffer.write(pickle.dumps(row))
    sys.stdout.flush()


if __name__ == "__main__":
    main()
