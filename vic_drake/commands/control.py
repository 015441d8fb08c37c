"""``vic-drake replay-qp``: the real controller's logs through our QP and tank."""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys

from vic_drake.commands.common import (
    add_bag_data_dir_option,
    add_json_option,
    bag_path,
    emit,
)
from vic_drake.errors import VicDrakeError


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "replay-qp",
        help="replay a real variable-impedance log through the stiffness QP and tank",
        description=(
            "Feeds each tick's logged inputs of a 31-column controller bag (position and "
            "velocity error, F_ref, F_min, the tank energy before the tick, the previous "
            "stiffness for the damping, dt from the timestamps) through the same QP and "
            "tank, and reports how closely K_z and the tank energy match the log. R is "
            "not logged: by default it is read off the log's K_z (the ticks where no "
            "bound or row is active give it in closed form; 0.1 for test_tracking5, "
            "1e-5 for test_nardi_matForce_lowR), or give it with --R."
        ),
    )
    parser.add_argument(
        "bag_dir",
        metavar="BAG_DIR",
        help="ROS 2 bag folder of a 31-column log (absolute, relative, or relative "
        "to the data folder, e.g. experiments/test_tracking5)",
    )
    parser.add_argument(
        "--R",
        dest="r_weight",
        type=float,
        default=None,
        metavar="R",
        help="stiffness regularisation weight R on every axis (> 0; default: read "
        "off the log's K_z)",
    )
    parser.add_argument(
        "--solver",
        choices=("osqp", "clarabel", "exact"),
        default="osqp",
        help="QP solver: osqp (default) or clarabel through Drake's MathematicalProgram, "
        "or exact, the closed-form solver (same answer, faster)",
    )
    add_bag_data_dir_option(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run_replay_qp)


@contextlib.contextmanager
def native_stdout_to_stderr():
    """Sends what native code writes to file descriptor 1 to stderr.

    OSQP's C code prints notes such as "Polishing not needed" on stdout even
    with verbose off; with ``--json`` stdout must hold the JSON alone.
    """
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # No real stdout (embedded use): nothing to protect.
        yield
        return
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def run_replay_qp(args: argparse.Namespace) -> int:
    from vic_drake.control.replay import replay_controller_log
    from vic_drake.realdata import read_bag

    r = args.r_weight
    if r is not None and not (math.isfinite(r) and r > 0.0):
        raise VicDrakeError(f"--R must be a finite number > 0; got {r!r}")
    bag = bag_path(
        args,
        args.bag_dir,
        expected="a ROS 2 bag folder (metadata.yaml + .db3) of a 31-column "
        "variable-impedance log",
    )
    log = read_bag(bag, expect="controller")  # Read once: for R and the replay.
    source = "--R"
    if r is None:  # A wrong R gives K_z errors of hundreds of N/m: read it.
        from vic_drake.analysis.r_weight_id import identify_r_weight

        r, source = identify_r_weight(log)["r_weight"], "read off the log's K_z"
    with native_stdout_to_stderr():
        result = replay_controller_log(log, r_weight=r, solver=args.solver)
    # The --json record keeps its keys (a contract); the text names R.
    summary = result.summary()
    human = (
        f"replay-qp {args.bag_dir} (R = {r:g}, {source}; solver {summary['solver']}): "
        f"{summary['ticks']} ticks, |K_z error| median {summary['kz_abs_err_median']:.3g}, "
        f"p99 {summary['kz_abs_err_p99']:.3g}, max {summary['kz_abs_err_max']:.3g} N/m; "
        f"tank |error| max {summary['tank_abs_err_max_J']:.3g} J; "
        f"{summary['failures']} failed solves\n"
        "settings read from the log: "
        + ", ".join(f"{k} = {v:g}" for k, v in result.from_log.items())
    )
    emit(summary, args.json, human)
    return 0
