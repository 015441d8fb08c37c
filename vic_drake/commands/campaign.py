"""``vic-drake campaign SPEC.yaml --out DIR``: a safety campaign on Dask.

Runs every run of a campaign spec (``campaigns/*.yaml``) on a local Dask
cluster (``--workers N`` processes, default: the machine's cores) or on an
existing one (``--scheduler tcp://host:port``), writes one row per run as it
finishes, and the summary (``summary.html``, ``summary.json``,
``results.parquet``). ``--resume`` finishes an interrupted campaign (or
starts it in a new or empty --out); a folder holding anything else is
refused.
"""

from __future__ import annotations

import argparse
import math

from vic_drake.commands.common import Progress, add_json_option, emit, help_text
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.dask_cluster import add_cluster_arguments

#: The keys --json prints (the command's contract), in order.
JSON_KEYS = (
    "runs",
    "finished",
    "failed",
    "nan_runs",
    "session_runs",
    "wall_s",
    "runs_per_hour",
    "workers",
    "per_controller",
)

#: The keys of each controller's entry.
CONTROLLER_KEYS = (
    "runs",
    "peak_force_N_p50",
    "peak_force_N_max",
    "exceed_prob",
    "exceed_prob_ci95",
    "contact_loss_s_p50",
    "tank_min_J",
)


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "campaign",
        help="run a safety campaign (many scans with sampled variations) on Dask",
        description=help_text(__doc__, 1),
    )
    p.add_argument(
        "spec", metavar="SPEC.yaml", help="the campaign spec (campaigns/*.yaml)"
    )
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    add_cluster_arguments(p, "the campaign's runs")
    p.add_argument(
        "--resume",
        action="store_true",
        help="finish the campaign already in --out (a new or empty --out: start it)",
    )
    p.add_argument(
        "--allow-code-change",
        action="store_true",
        help="with --resume: add this code's rows to rows other code computed "
        "(refused otherwise: another vic_drake source, Drake or Python; the "
        "summary then counts the rows per code)",
    )
    add_json_option(p)
    p.set_defaults(handler=run_campaign_command)


def _num(value: float, width: int, digits: int) -> str:
    """A number of the console table; "-" where there is none (NaN: e.g. the
    tank of CS and CF, which have none), as in the README's tables."""
    text = "-" if value is None or math.isnan(value) else f"{value:.{digits}f}"
    return f"{text:>{width}}"


def _human(result: dict) -> str:
    from vic_drake.experiments.campaign.legend import console_legend

    new = result["session_runs"]
    before = result["finished"] - new
    if new:
        # The time and the rate are this session's: its runs alone.
        session = (
            f"this session {new} runs in {result['wall_s']:.0f} s on "
            f"{result['workers']} worker{'' if result['workers'] == 1 else 's'}, "
            f"{result['runs_per_hour']:.0f} runs/h"
        )
        if before:
            session += f" ({before} finished before)"
    else:
        session = "nothing left to run"
    width = max([10, *(len(name) for name in result["per_controller"])])
    limit = result["force_limit_N"]
    lines = [
        f"{result['finished']}/{result['runs']} runs done: "
        f"{result['finished'] - result['failed']} ok, {result['failed']} failed "
        f"({result['nan_runs']} of them NaN); {session}",
        f"{'controller':<{width}} {'runs':>5} {'no contact':>10} {'peakF p50':>10} "
        f"{'peakF max':>10} {f'P(>{limit:g} N)':>10} {'95% CI':>16} "
        f"{'loss p50 s':>10} {'tank min J':>10} {'wd stops':>8}",
    ]
    for name, v in result["per_controller"].items():
        lo, hi = v["exceed_prob_ci95"]
        ci = f"[{_num(lo, 0, 3)}, {_num(hi, 0, 3)}]"
        lines.append(
            f"{name:<{width}} {v['runs']:>5} {v['no_contact_runs']:>10} "
            f"{_num(v['peak_force_N_p50_contact'], 10, 2)} "
            f"{_num(v['peak_force_N_max'], 10, 2)} {_num(v['exceed_prob'], 10, 3)} "
            f"{ci:>16} {_num(v['contact_loss_s_p50'], 10, 3)} "
            f"{_num(v['tank_min_J'], 10, 3)} {v['watchdog_stops']:>8}"
        )
    lines += [f"  {line}" for line in console_legend(limit)]
    codes = result.get("code_ids", {})
    if len(codes) > 1:
        lines.append(
            "rows from more than one code (--allow-code-change): "
            + "; ".join(f"{n} by {c}" for c, n in codes.items())
        )
    for c in result.get("paired", []):
        loss, over = c["contact_loss"], c["exceedance"]
        lines.append(
            f"paired, {c['second']} - {c['first']} ({c['pairs']} pairs): peakF "
            f"p50 {c['peak_force_diff_N_p50']:+.2f} N "
            f"[{c['peak_force_diff_N_p10']:+.2f}, {c['peak_force_diff_N_p90']:+.2f}]; "
            f"contact lost by {c['second']} alone in {loss['only_second']}, by "
            f"{c['first']} alone in {loss['only_first']} (McNemar p "
            f"{loss['mcnemar_p']:.3g}); above the limit alone: {over['only_second']}"
            f" / {over['only_first']}"
        )
    return "\n".join(lines)


def run_campaign_command(args: argparse.Namespace) -> int:
    from vic_drake.experiments.campaign import run_campaign

    if args.allow_code_change and not args.resume:
        raise VicDrakeError(
            "--allow-code-change goes with --resume (it lets a resume mix codes)"
        )
    result = run_campaign(
        args.spec,
        args.out,
        workers=args.workers,
        scheduler=args.scheduler,
        resume=args.resume,
        progress=Progress(True),
        allow_code_change=args.allow_code_change,
    )
    out = {key: result[key] for key in JSON_KEYS}
    out["per_controller"] = {
        name: {key: v[key] for key in CONTROLLER_KEYS}
        for name, v in result["per_controller"].items()
    }
    # The paired comparison, the watchdog's stops, the runs without contact
    # and the force limit are in summary.json and the table in words; --json
    # keeps its keys.
    human = {
        **out,
        "force_limit_N": result["force_limit_N"],
        "per_controller": result["per_controller"],
        "paired": result.get("paired", []),
        "code_ids": result.get("code_ids", {}),
    }
    emit(out, args.json, _human(human))
    return 0 if out["failed"] == 0 else 1
