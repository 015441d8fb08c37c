"""A campaign's outputs: results.parquet, summary.json and summary.html.

The page shows each controller's distribution of peak force and contact
loss, the probability of exceeding the force limit with its 95 % Wilson
interval, a legend of those columns, each factor's effect on the peak force
(or, with too few runs per controller, that there are too few), and the ten
worst runs with the command that replays each. A table is never shown
without rows: where there is nothing to tabulate the page says why.
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
import os
import shlex
from pathlib import Path

import numpy as np
import pandas as pd

from vic_drake.experiments.campaign.legend import (
    controller_legend,
    exceed_label,
    worst_runs_legend,
)
from vic_drake.experiments.campaign.spec import CampaignSpec
from vic_drake.experiments.campaign.stats import (
    MIN_EFFECT_RUNS,
    factor_effects,
    touched,
    worst_runs,
)
from vic_drake.jsonio import to_json
from vic_drake.paper import CONTACT_THRESHOLD_N


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
    # Many arms ("vs-vf no watchdog", ...): slanted names, which need height.
    slant = len(names) > 4
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5 if slant else 3.5))
    for ax, col, label in (
        (axes[0], "peak_force_N", "peak force on the patient,\nruns that touched (N)"),
        (axes[1], "contact_loss_s", "contact loss in the scan (s)"),
    ):
        data = []
        for n in names:
            v = ok.loc[ok["factor.controller"] == n, col].dropna().to_numpy(float)
            if col == "peak_force_N":  # A run that never touched has no peak
                v = v[touched(v)]  # (the table counts them).
            data.append(v)
        if names:
            ax.boxplot(data, showfliers=True)
            ax.set_xticks(range(1, len(names) + 1), names)
            if slant:
                ax.tick_params(axis="x", labelrotation=35)
                for tick in ax.get_xticklabels():
                    tick.set_horizontalalignment("right")
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


def _table(header, body, *, empty: str = "Nothing to show.") -> str:
    """A table, or the sentence ``empty`` where it has no rows."""
    if not body:
        return f"<p>{html.escape(empty)}</p>"
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
        empty="No pair of runs in which both arms finished.",
    )


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def _header(spec: CampaignSpec, summary: dict) -> list[str]:
    """The title, the campaign as run (its spec's fields) and its outcome.

    The spec's free-text description may quote other figures (a spec copied
    and shortened keeps "200 runs of 4 s"): it is shown as the spec's words,
    after the fields.
    """
    extras = "".join(
        text
        for flag, text in (
            (spec.population, ", a synthetic patient per run"),
            (spec.paired, ", the arms paired run for run"),
        )
        if flag
    )
    parts = [
        f"<h1>Campaign {html.escape(spec.name)}</h1>",
        f"<p>As run: <b>{_plural(spec.runs, 'run')} of {spec.duration_s:g} s</b>"
        f" (seed {spec.seed}{extras}); force limit {spec.force_limit_N:g} N on "
        "the patient.</p>",
    ]
    if spec.description:
        parts.append(
            f"<p>The spec's description: <q>{html.escape(spec.description)}</q></p>"
        )
    parts.append(_factors_html(spec))
    parts.append(
        f"<p>{summary['finished']} of {summary['runs']} runs done: "
        f"{summary['finished'] - summary['failed']} ok, {summary['failed']} failed "
        f"({summary['nan_runs']} of them NaN).</p>"
    )
    codes = summary.get("code_ids", {})
    if len(codes) == 1:
        parts.append(f"<p>Computed by {html.escape(next(iter(codes)))}.</p>")
    elif codes:
        mixed = "; ".join(f"{n} by {html.escape(c)}" for c, n in codes.items())
        parts.append(
            "<p><b>The rows come from more than one code</b> (a resume with "
            f"--allow-code-change): {mixed}.</p>"
        )
    return parts


def _factors_html(spec: CampaignSpec) -> str:
    """What the campaign varies: each factor's field and distribution."""

    def drawn(f) -> str:
        if f.dist == "uniform":
            return f"uniform from {f.low:g} to {f.high:g}"
        if f.dist == "normal":
            clip = f", clipped to [{f.low:g}, {f.high:g}]" if f.low < f.high else ""
            return f"normal, mean {f.mean:g}, std {f.std:g}{clip}"
        levels = ", ".join(str(v) if isinstance(v, str) else f"{v:g}" for v in f.levels)
        if f.dist == "grid":
            return f"grid: {levels} (each round of runs has every one)"
        return f"choice of {levels} (one drawn per run)"

    rows = [[html.escape(f.field), html.escape(drawn(f))] for f in spec.factors]
    if spec.population:
        rows.append(["patient", "a synthetic patient drawn per round"])
    return "<h2>What varies</h2>" + _table(
        ["factor (scenario field)", "drawn"], rows, empty="Nothing varies."
    )


def _legend(items: list[tuple[str, str]]) -> str:
    return (
        "<ul class='legend'>"
        + "".join(
            f"<li><b>{html.escape(k)}</b>: {html.escape(v)}</li>" for k, v in items
        )
        + "</ul>"
    )


def _controller_html(summary: dict, force_limit_N: float) -> str:
    """The per-controller table and its legend."""
    table = _table(
        [
            "controller",
            "runs",
            "never touched the patient",
            "peak F p50 (N)",
            "peak F max (N)",
            exceed_label(force_limit_N),
            "95 % interval (Wilson)",
            "contact loss p50 (s)",
            "tank min (J)",
            "stopped by the sensor watchdog",
        ],
        [
            [
                html.escape(n),
                v["runs"],
                v["no_contact_runs"],
                _fmt(v["peak_force_N_p50_contact"]),
                _fmt(v["peak_force_N_max"]),
                _fmt(v["exceed_prob"]),
                _fmt(v["exceed_prob_ci95"]),
                _fmt(v["contact_loss_s_p50"]),
                _fmt(v["tank_min_J"]),
                v["watchdog_stops"],
            ]
            for n, v in summary["per_controller"].items()
        ],
        empty="No run has finished.",
    )
    legend = (
        _legend(controller_legend(force_limit_N)) if summary["per_controller"] else ""
    )
    return "<h2>Per controller</h2>" + table + legend


def _effects_html(touched: pd.DataFrame, untouched: int) -> tuple[str, list[str]]:
    """The factor effects on the peak force of the runs that touched the
    patient, in words and tables; and the numeric factors whose effect was
    computed (each gets a figure)."""
    parts = ["<h2>Factor effects on the peak force</h2>"]
    if untouched and not touched.empty:
        parts.append(
            f"<p>Over the runs that touched the patient: {_plural(untouched, 'run')} "
            f"without contact (peak F at most {CONTACT_THRESHOLD_N:g} N) left out.</p>"
        )
    effects = factor_effects(touched)
    if not effects:
        parts.append(
            "<p>No run touched the patient.</p>"
            if touched.empty
            else "<p>No factor besides the controller varies in this campaign.</p>"
        )
    by_kind = {
        kind: [e for e in effects if e["kind"] == kind]
        for kind in ("too_few", "numeric", "levels", "constant")
    }
    too_few = {e["controller"]: e["runs"] for e in by_kind["too_few"]}
    if too_few:
        counts = set(too_few.values())
        each = ", ".join(f"{c}: {n}" for c, n in too_few.items())
        if len(too_few) < len({e["controller"] for e in effects}):
            which = f"for {each}"
        else:
            which = f"per controller ({counts.pop() if len(counts) == 1 else each})"
        parts.append(
            f"<p>Too few runs {which} for factor effects: they need at least "
            f"{MIN_EFFECT_RUNS} runs of a controller (with 4, even a perfect "
            "rank correlation is within chance).</p>"
        )
    if by_kind["numeric"]:
        parts.append(
            _table(
                [
                    "factor",
                    "controller",
                    "runs",
                    "Spearman rho",
                    "p (two-sided)",
                    "median, lowest third (N)",
                    "median, highest third (N)",
                ],
                [
                    [
                        html.escape(e["factor"]),
                        html.escape(e["controller"]),
                        str(e["runs"]),
                        f"{e['spearman']:.2f}"
                        if e["spearman"] == e["spearman"]
                        else "—",
                        _fmt(e["spearman_p"]),
                        _fmt(e["low_third_median"]),
                        _fmt(e["high_third_median"]),
                    ]
                    for e in by_kind["numeric"]
                ],
            )
        )
    if by_kind["levels"]:
        parts.append(
            _table(
                ["factor", "controller", "median peak F per value (N; runs)"],
                [
                    [
                        html.escape(e["factor"]),
                        html.escape(e["controller"]),
                        ", ".join(
                            f"{html.escape(k)}: {_fmt(m)} ({e['runs'][k]})"
                            for k, m in e["medians"].items()
                        ),
                    ]
                    for e in by_kind["levels"]
                ],
            )
        )
    constant: dict[str, dict[str, list[str]]] = {}
    for e in by_kind["constant"]:
        values = constant.setdefault(e["factor"], {})
        values.setdefault(_fmt(e["value"]), []).append(html.escape(e["controller"]))
    if constant:
        n_controllers = len({e["controller"] for e in effects})
        held = [
            f"{html.escape(f)} = {v}"
            + ("" if len(c) == n_controllers else f" ({', '.join(c)})")
            for f, values in constant.items()
            for v, c in values.items()
        ]
        parts.append(
            "<p>One value in a controller's runs (no effect to measure): "
            + "; ".join(held)
            + ".</p>"
        )
    numeric = list(dict.fromkeys(e["factor"] for e in by_kind["numeric"]))
    return "".join(parts), numeric


def _watchdog_text(r) -> str:
    trip = r.get("watchdog_trip_s", math.nan)
    if not isinstance(trip, float) or math.isnan(trip):
        return "—"
    return f"{trip:.3g} s ({html.escape(str(r.get('watchdog_cause', '')))})"


def _worst_html(out: Path, rows: pd.DataFrame) -> str:
    worst = worst_runs(rows)
    table = _table(
        [
            "run",
            "controller",
            "status",
            "peak F (N)",
            "contact loss (s)",
            "tank min (J)",
            "watchdog stop",
            "failed QP solves / skipped ticks",
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
                _watchdog_text(r),
                f"{_fmt(r.get('qp_failures', math.nan))} / "
                f"{_fmt(r.get('input_faults', math.nan))}",
                html.escape(str(r["error"])),
                f"<code>{html.escape(replay_command(out, r['run_id']))}</code>",
            ]
            for _, r in worst.iterrows()
        ],
    )
    legend = _legend(worst_runs_legend())
    return "<h2>The ten worst runs</h2>" + table + legend


def summary_html(
    out: Path, spec: CampaignSpec, rows: pd.DataFrame, summary: dict
) -> str:
    """The campaign's summary page."""
    parts = _header(spec, summary)
    parts.append(_controller_html(summary, spec.force_limit_N))
    if summary.get("paired"):
        parts.append(_paired_html(summary["paired"], spec.force_limit_N))
    if not rows.empty:
        parts.append(_png(distribution_figure(rows, spec.force_limit_N)))
        scored = rows[rows["status"] != "error"]
        peaks = scored["peak_force_N"].to_numpy(float)
        in_contact = touched(peaks)
        untouched = int(np.sum(np.isfinite(peaks) & ~in_contact))
        text, numeric = _effects_html(scored[in_contact], untouched)
        parts.append(text)
        parts.extend(
            _png(effect_figure(scored[in_contact], factor)) for factor in numeric
        )
        parts.append(_worst_html(out, rows))
    style = (
        "<style>table{border-collapse:collapse}"
        "td,th{border:1px solid #ccc;padding:2px 6px}"
        ".legend{font-size:90%;max-width:60em}</style>"
    )
    return f"<html><head><meta charset='utf-8'>{style}</head><body>{''.join(parts)}</body></html>"


def replay_command(out: Path, run_id: str) -> str:
    """The command that replays one run, from any folder (the path made
    absolute, quoted for a shell where it needs it)."""
    path = Path(out).resolve() / "scenarios" / f"{run_id}.yaml"
    return f"vic-drake scan {shlex.quote(str(path))}"


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
    _atomic(out / "summary.json", to_json(summary).encode())
    _atomic(out / "summary.html", summary_html(out, spec, rows, summary).encode())


__all__ = ["replay_command", "summary_html", "write_outputs"]
