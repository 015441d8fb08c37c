"""A campaign's outputs: results.parquet, summary.json and summary.html.

The page shows each controller's distribution of peak force and contact
loss, the probability of exceeding the force limit with its 95 % Wilson
interval, each factor's effect on the peak force, and the ten worst runs
with the command that replays each.
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
import os
from pathlib import Path

import numpy as np
import pandas as pd

from vic_drake.experiments.campaign.spec import CampaignSpec
from vic_drake.experiments.campaign.stats import factor_effects, worst_runs


def _atomic(path: Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _fmt(v) -> str:
    if isinstance(v, float):
        # No value (a failed run's metrics; CS's and CF's tank, which they
        # do not have): a dash, as in the reproduce report.
        return "—" if math.isnan(v) else f"{v:.4g}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return html.escape(str(v))


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close(fig)
    return (
        f'<img src="data:image/png;base64,{base64.b64encode(buf.getvalue()).decode()}">'
    )


def distribution_figure(rows: pd.DataFrame, force_limit_N: float):
    """Box plots of peak force and contact loss per controller."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = rows[rows["status"] != "error"]
    names = sorted(ok["factor.controller"].astype(str).unique())
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.5))
    for ax, col, label in (
        (axes[0], "peak_force_N", "peak force on the patient (N)"),
        (axes[1], "contact_loss_s", "contact loss in the scan (s)"),
    ):
        data = [
            ok.loc[ok["factor.controller"] == n, col].dropna().to_numpy() for n in names
        ]
        if names:
            ax.boxplot(data, showfliers=True)
            ax.set_xticks(range(1, len(names) + 1), names)
        ax.set_ylabel(label)
    axes[0].axhline(force_limit_N, color="r", ls="--", label="force limit")
    axes[0].legend()
    fig.tight_layout()  # The second axis label clears the first plot.
    return fig


def effect_figure(rows: pd.DataFrame, factor: str):
    """Peak force against one numeric factor, one colour per controller."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = rows[rows["status"] != "error"]
    fig, ax = plt.subplots(figsize=(4.5, 3.2))
    for name, g in ok.groupby("factor.controller"):
        ax.plot(g[f"factor.{factor}"], g["peak_force_N"], "o", ms=3, label=str(name))
    ax.set_xlabel(factor)
    ax.set_ylabel("peak force (N)")
    ax.legend(fontsize=7)
    return fig


def _table(header, body) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    rows = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>" for r in body)
    return f"<table><tr>{head}</tr>{rows}</table>"


def _paired_html(paired: list[dict], force_limit_N: float) -> str:
    """The arms run for run (a paired campaign)."""

    def counts(c: dict) -> str:
        return (
            f"{c['only_first']} / {c['only_second']} / {c['both']} "
            f"(p = {_fmt(c['mcnemar_p'])})"
        )

    return "<h2>Paired arms (each pair under the same draws)</h2>" + _table(
        [
            "first arm",
            "second arm",
            "pairs",
            "peak F, second minus first: p50 [p10, p90] (N)",
            "contact loss: first only / second only / both (McNemar p)",
            f"peak F > {force_limit_N:g} N: first only / second only / both",
        ],
        [
            [
                html.escape(c["first"]),
                html.escape(c["second"]),
                c["pairs"],
                f"{_fmt(c['peak_force_diff_N_p50'])} "
                f"[{_fmt(c['peak_force_diff_N_p10'])}, "
                f"{_fmt(c['peak_force_diff_N_p90'])}]",
                counts(c["contact_loss"]),
                counts(c["exceedance"]),
            ]
            for c in paired
        ],
    )


def summary_html(
    out: Path, spec: CampaignSpec, rows: pd.DataFrame, summary: dict
) -> str:
    """The campaign's summary page."""
    parts = [
        f"<h1>Campaign {html.escape(spec.name)}</h1>",
        f"<p>{html.escape(spec.description)}</p>",
        f"<p>{summary['finished']} of {summary['runs']} runs finished, "
        f"{summary['failed']} failed ({summary['nan_runs']} NaN); force limit "
        f"{spec.force_limit_N} N; {spec.duration_s} s per run.</p>",
    ]
    pc = summary["per_controller"]
    parts.append("<h2>Per controller</h2>")
    parts.append(
        _table(
            [
                "controller",
                "runs",
                "peak F p50 (N)",
                "peak F max (N)",
                "P(peak > limit)",
                "95 % interval (Wilson)",
                "contact loss p50 (s)",
                "tank min (J)",
                "stopped by the sensor watchdog",
            ],
            [
                [
                    html.escape(n),
                    v["runs"],
                    _fmt(v["peak_force_N_p50"]),
                    _fmt(v["peak_force_N_max"]),
                    _fmt(v["exceed_prob"]),
                    _fmt(v["exceed_prob_ci95"]),
                    _fmt(v["contact_loss_s_p50"]),
                    _fmt(v["tank_min_J"]),
                    v["watchdog_stops"],
                ]
                for n, v in pc.items()
            ],
        )
    )
    if summary.get("paired"):
        parts.append(_paired_html(summary["paired"], spec.force_limit_N))
    if not rows.empty:
        parts.append(_png(distribution_figure(rows, spec.force_limit_N)))
        effects = factor_effects(rows)
        parts.append("<h2>Factor effects on the peak force</h2>")
        numeric = [e for e in effects if e["kind"] == "numeric"]
        parts.append(
            _table(
                [
                    "factor",
                    "controller",
                    "Spearman rho",
                    "median, lowest third (N)",
                    "median, highest third (N)",
                ],
                [
                    [
                        html.escape(e["factor"]),
                        html.escape(e["controller"]),
                        _fmt(e["spearman"]),
                        _fmt(e["low_third_median"]),
                        _fmt(e["high_third_median"]),
                    ]
                    for e in numeric
                ],
            )
        )
        for e in (e for e in effects if e["kind"] == "levels"):
            parts.append(
                f"<p>{html.escape(e['factor'])} ({html.escape(e['controller'])}): "
                + ", ".join(
                    f"{html.escape(k)}: {_fmt(v)} N" for k, v in e["medians"].items()
                )
                + "</p>"
            )
        for factor in dict.fromkeys(e["factor"] for e in numeric):
            parts.append(_png(effect_figure(rows, factor)))
        parts.append("<h2>The ten worst runs</h2>")
        worst = worst_runs(rows)
        parts.append(
            _table(
                [
                    "run",
                    "controller",
                    "status",
                    "peak F (N)",
                    "contact loss (s)",
                    "tank min (J)",
                    "error",
                    "replay",
                ],
                [
                    [
                        r["run_id"],
                        html.escape(str(r["factor.controller"])),
                        r["status"],
                        _fmt(r["peak_force_N"]),
                        _fmt(r["contact_loss_s"]),
                        _fmt(r["tank_min_J"]),
                        html.escape(str(r["error"])),
                        f"<code>{html.escape(replay_command(out, r['run_id']))}</code>",
                    ]
                    for _, r in worst.iterrows()
                ],
            )
        )
    style = "<style>table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px}</style>"
    return f"<html><head><meta charset='utf-8'>{style}</head><body>{''.join(parts)}</body></html>"


def replay_command(out: Path, run_id: str) -> str:
    """The command that replays one run."""
    return f"vic-drake scan {out / 'scenarios' / f'{run_id}.yaml'}"


def write_outputs(
    out: Path, spec: CampaignSpec, rows: pd.DataFrame, summary: dict
) -> None:
    """Writes results.parquet, summary.json and summary.html (each atomically)."""
    out = Path(out)
    if not rows.empty:
        table = rows.copy()
        for col in table.columns:  # Mixed label/number factors: store as text.
            if table[col].dtype == object:
                table[col] = table[col].map(
                    lambda v: v if isinstance(v, str) else json.dumps(v)
                )
        buf = io.BytesIO()
        table.to_parquet(buf, index=False)
        _atomic(out / "results.parquet", buf.getvalue())
    _atomic(
        out / "summary.json",
        json.dumps(summary, indent=2, default=_json_default).encode(),
    )
    _atomic(out / "summary.html", summary_html(out, spec, rows, summary).encode())


def _json_default(v):
    if isinstance(v, np.generic):
        return v.item()
    raise TypeError(type(v).__name__)


__all__ = ["replay_command", "summary_html", "write_outputs"]
