"""``vic-drake estimate-online BAG``: an online estimator replayed over a
real log; ``vic-drake compare-online SCENARIO``: the closed loop on the
online estimates against the true and the wrong maps.

``estimate-online`` runs the recursive least squares or the EKF tick by
tick over a palpation log (6 columns; reference: the offline least-squares
Hunt-Crossley fit of the whole log) or a variable-impedance scan log (31
columns; reference: the map's kappa and lambda the controller logged at the
probe's (x, y): on the rig, the measured GP map), and prints the median relative errors, the correlation of kappa
with the reference, the convergence time and the tick cost.

``compare-online`` simulates the scenario's VS-VF scan on the true map, on
wrong maps (kappa x 1.3 or x 0.7, surface 2 mm high) and on the online
estimates, at one or several dither frequencies, and scores each run
against the TRUE tissue: force RMSE, p99 force over the ribs, kappa error,
tank minimum. With several frequencies each cell is the mean (min-max);
``--against RUN`` counts the frequencies at which each run is below RUN.
More than one scan runs on Dask, each scan in a process of its own: a
local cluster (``--workers N``, default the cores) or an existing one
(``--scheduler ADDRESS``).
"""

from __future__ import annotations

import argparse
import math

from vic_drake.commands.common import (
    Progress,
    add_bag_data_dir_option,
    add_json_option,
    bag_path,
    emit,
    fmt_number,
    help_text,
)
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.online_sweep import add_comparison_arguments


def _estimate_online(args: argparse.Namespace) -> int:
    from vic_drake.estimation.online import OnlineEstimatorParams
    from vic_drake.experiments.online_replay import replay_online

    if args.lag is not None and not (
        math.isfinite(args.lag) and 0.0 <= args.lag <= 1.0
    ):
        raise VicDrakeError(f"--lag must be in [0, 1] s; got {args.lag!r}")
    if not (math.isfinite(args.beta) and 0.0 < args.beta <= 3.0):
        raise VicDrakeError(f"--beta must be in (0, 3]; got {args.beta!r}")
    path = bag_path(
        args,
        args.bag_dir,
        "bag",
        "a ROS 2 bag folder (metadata.yaml + .db3) of the 6-column palpation or "
        "the 31-column variable-impedance layout",
    )
    if args.surface_walk is not None and args.method != "ekf":
        raise VicDrakeError(
            "--surface-walk needs --method ekf (the RLS trusts the surface)"
        )
    walk = 0.0 if args.surface_walk is None else args.surface_walk
    if not (math.isfinite(walk) and 0.0 <= walk <= 0.1):
        raise VicDrakeError(
            f"--surface-walk must be in [0, 0.1] m/sqrt(s); got {walk!r}"
        )
    params = OnlineEstimatorParams(
        method=args.method, beta=args.beta, surface_walk_m_per_sqrt_s=walk
    )
    say = Progress()
    say(f"replaying {args.bag_dir} through the {args.method.upper()} estimator")
    result = replay_online(path, params=params, lag_s=args.lag)
    s = result.summary
    ref = (
        "offline least-squares fit of the whole log"
        if result.kind == "palpation"
        else "the map's kappa and lambda the controller logged at the probe's (x, y)"
    )

    human = "\n".join(
        [
            f"{result.kind} {args.bag_dir}: {s['samples']} samples, method {s['method']}, "
            f"force paired with the position {result.lag_s * 1e3:.1f} ms earlier",
            f"reference: {ref}",
            f"kappa: median relative error {fmt_number(s['kappa_rel_err_median'], '.3f')}, "
            "correlation "
            + (
                "n/a (one point pressed: nothing to correlate along a path)"
                if result.kind == "palpation"
                else fmt_number(s["kappa_corr"], ".3f")
            )
            + ", at the last contact sample "
            f"{fmt_number(result.final_kappa_rel_err, '.3f')}",
            f"lambda: median relative error {fmt_number(s['lambda_rel_err_median'], '.3f')}",
            _convergence_line(s["convergence_s"]),
            f"tick cost p99 {s['tick_us_p99']:.1f} us (as a function)",
        ]
    )
    emit(s, args.json, human)
    return 0


def _convergence_line(convergence_s) -> str:
    """The convergence time in words; NaN/None: not reached (convergence_time_s)."""
    if convergence_s is None or not math.isfinite(convergence_s):
        return (
            "convergence (kappa stays within 10 %): not reached (kappa is more than "
            "10 % off the reference at the last contact sample, or the log has no "
            "contact)"
        )
    return (
        f"convergence (kappa stays within 10 %): {convergence_s:.2f} s after first "
        "contact"
    )


def _compare_online(args: argparse.Namespace) -> int:
    from vic_drake.experiments.online_sweep import (
        comparison_report,
        run_comparison,
        sweep_json,
    )

    sweep = run_comparison(args, Progress())
    emit(
        sweep_json(sweep, args.dither_hz, args.against),
        args.json,
        comparison_report(sweep, args.dither_hz, args.against),
    )
    return 0


def register(subparsers) -> None:
    """Adds ``estimate-online`` and ``compare-online``."""
    p = subparsers.add_parser(
        "estimate-online",
        help="replay an online kappa/lambda estimator over a real log",
        description=help_text(__doc__, 1),
    )
    p.add_argument(
        "bag_dir",
        metavar="BAG",
        help="bag folder: 6-column palpation or 31-column VS scan (absolute, "
        "relative, or relative to the data folder)",
    )
    p.add_argument(
        "--method",
        choices=("rls", "ekf"),
        default="rls",
        help="recursive least squares with forgetting, or the EKF (default %(default)s)",
    )
    p.add_argument(
        "--lag",
        type=float,
        default=None,
        metavar="S",
        help="force-after-position delay, s (default: the offline estimate on a "
        "palpation, 0 on a scan)",
    )
    p.add_argument(
        "--beta",
        type=float,
        default=1.35,
        help="Hunt-Crossley exponent, in (0, 3] (default %(default)s)",
    )
    p.add_argument(
        "--surface-walk",
        type=float,
        default=None,
        metavar="M",
        help="EKF only: estimate a surface offset too, with this random walk in "
        "m/sqrt(s) (default: trust the surface of the log or map)",
    )
    add_bag_data_dir_option(p)
    add_json_option(p)
    p.set_defaults(handler=_estimate_online)

    q = subparsers.add_parser(
        "compare-online",
        help="VS-VF on the true map, wrong maps and online estimates, scored "
        "against the true tissue",
        description=help_text(__doc__, 2),
    )
    add_comparison_arguments(q)
    add_json_option(q)
    q.set_defaults(handler=_compare_online)
