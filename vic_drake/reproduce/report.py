"""A self-contained HTML report of a reproduction run.

One file, no external resources: figures are embedded as base64 PNG, tables
are plain HTML. It holds the claims table (paper / simulation / real /
pass), the paper-style figures, any extra tables (e.g. Table I) and the run's
metadata (versions, data folder, wall time of every stage).

:func:`render_report` builds the HTML text from plain inputs;
:func:`write_report` writes it. Nothing here runs simulations.
"""

from __future__ import annotations

import base64
import html
import io
import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vic_drake.analysis.claims.claim import FAIL, NOT_EVALUATED, PASS, claim_status


@dataclass
class ReportFigure:
    """A figure of the report.

    Attributes:
        title: heading, e.g. "Fig. 2 - load test".
        caption: what the figure shows, and how it maps to the paper's figure.
        png: PNG bytes, a path to a PNG file, or a matplotlib Figure.
    """

    title: str
    caption: str
    png: Any

    def png_bytes(self) -> bytes:
        if isinstance(self.png, (bytes, bytearray)):
            return bytes(self.png)
        if isinstance(self.png, (str, os.PathLike)):
            return Path(self.png).read_bytes()
        if hasattr(self.png, "savefig"):
            buf = io.BytesIO()
            self.png.savefig(buf, format="png", dpi=110, bbox_inches="tight")
            return buf.getvalue()
        raise TypeError(
            f"ReportFigure.png must be bytes, a path or a Figure, got {type(self.png)}"
        )


@dataclass
class ReportTable:
    """A table: a caption, column names and rows of cells (any printable value)."""

    title: str
    columns: Sequence[str]
    rows: Sequence[Sequence[Any]]
    caption: str = ""


@dataclass
class ReportContent:
    """Everything the report shows.

    Attributes:
        title: page title.
        summary: a short paragraph under the title.
        claims: {"C1": {"statement","paper","sim","real","pass", ...}, ...}.
        figures: figures in order.
        tables: extra tables (Table I, per-run metrics).
        metadata: {label: value} (versions, data folder, mode).
        stages: [{"name", "ok", "wall_s", "error"}] per pipeline stage.
        links: [(text, relative href)] (e.g. the Meshcat replay, logs).
        notes: short remarks on how to read the results (a bullet list).
    """

    title: str = "vic_drake reproduction report"
    summary: str = ""
    claims: Mapping[str, Mapping] = field(default_factory=dict)
    figures: list[ReportFigure] = field(default_factory=list)
    tables: list[ReportTable] = field(default_factory=list)
    metadata: Mapping[str, Any] = field(default_factory=dict)
    stages: Sequence[Mapping[str, Any]] = field(default_factory=list)
    links: Sequence[tuple[str, str]] = field(default_factory=list)
    notes: Sequence[str] = field(default_factory=list)


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:2em auto;
max-width:1300px;color:#222;line-height:1.4;padding:0 1em}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
.tablewrap{overflow-x:auto;max-width:100%;margin:.6em 0}
table{border-collapse:collapse;font-size:.9em;width:100%}
th,td{border:1px solid #ccc;padding:.3em .5em;vertical-align:top;text-align:left;
overflow-wrap:break-word}
td.pass,td.fail,td.ne,td.na{white-space:nowrap}
td.stmt{width:24%}
th{font-size:.92em}
th{background:#f3f3f3}
td.pass{background:#dff5df;font-weight:bold;color:#175c17}
td.fail{background:#fadede;font-weight:bold;color:#8a1414}
td.na{color:#777}
td.ne{background:#f0f0f0;color:#555;font-style:italic}
pre.val{margin:0;font-size:.85em;white-space:pre-wrap;overflow-wrap:anywhere;
font-family:ui-monospace,Menlo,Consolas,monospace}
figure{margin:1em 0;page-break-inside:avoid}figure img{max-width:100%;border:1px solid #eee}
figcaption{font-size:.9em;color:#444}
.small{font-size:.85em;color:#555}
"""


def _fmt_number(v: float) -> str:
    if not np.isfinite(v):
        return "n/a"
    if v == 0:
        return "0"
    a = abs(v)
    if a >= 1e4 or a < 1e-3:
        return f"{v:.3e}"
    return f"{v:.4g}"


def format_value(value: Any) -> str:
    """Compact text of a claim value (dicts one key per line)."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return _fmt_number(float(value))
    if isinstance(value, Mapping):
        lines = []
        for k, v in value.items():
            if isinstance(v, Mapping) and v:
                inner = format_value(v).replace("\n", "\n  ")
                lines.append(f"{k}:\n  {inner}")
            else:
                lines.append(f"{k}: {format_value(v)}")
        return "\n".join(lines)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    return str(value)


def _cell(value: Any) -> str:
    if value is None:
        return '<td class="na">—</td>'
    return f'<td><pre class="val">{html.escape(format_value(value))}</pre></td>'


def _pass_cell(ok: bool | None) -> str:
    if ok is None:
        return '<td class="na">not evaluated</td>'
    return '<td class="pass">PASS</td>' if ok else '<td class="fail">FAIL</td>'


def _status_cell(status: str) -> str:
    if status == PASS:
        return '<td class="pass">PASS</td>'
    if status == FAIL:
        return '<td class="fail">FAIL</td>'
    return '<td class="ne">not evaluated</td>'


def _wrap(table: str) -> str:
    """A table in a box that scrolls sideways when it is wider than the page."""
    return f'<div class="tablewrap">{table}</div>'


def claims_table_html(claims: Mapping[str, Mapping]) -> str:
    """The claims table: id, statement, paper, simulation, real, verdicts."""
    rows = []
    for cid, c in claims.items():
        detail = c.get("detail") or ""
        rows.append(
            "<tr>"
            f"<td><b>{html.escape(cid)}</b></td>"
            f'<td class="stmt">{html.escape(str(c.get("statement", "")))}'
            f'<div class="small">{html.escape(detail)}</div></td>'
            f"{_cell(c.get('paper'))}{_cell(c.get('sim'))}{_cell(c.get('real'))}"
            f"{_pass_cell(c.get('pass_sim'))}{_pass_cell(c.get('pass_real'))}"
            f"{_status_cell(claim_status(c))}"
            "</tr>"
        )
    head = (
        "<tr><th>id</th><th>claim</th><th>paper</th><th>simulation</th>"
        "<th>real measurement</th><th>sim</th><th>real</th><th>verdict</th></tr>"
    )
    return _wrap(f"<table>{head}{''.join(rows)}</table>")


def _header(name: str) -> str:
    """A column name that may break after its underscores."""
    return html.escape(name).replace("_", "_<wbr>")


def table_html(table: ReportTable) -> str:
    head = "".join(f"<th>{_header(str(c))}</th>" for c in table.columns)
    body = "".join(
        "<tr>"
        + "".join(f"<td>{html.escape(format_value(v))}</td>" for v in row)
        + "</tr>"
        for row in table.rows
    )
    cap = f'<p class="small">{html.escape(table.caption)}</p>' if table.caption else ""
    return (
        f"<h3>{html.escape(table.title)}</h3>"
        + _wrap(f"<table><tr>{head}</tr>{body}</table>")
        + cap
    )


def figure_html(fig: ReportFigure) -> str:
    data = base64.b64encode(fig.png_bytes()).decode("ascii")
    return (
        f"<figure><h3>{html.escape(fig.title)}</h3>"
        f'<img alt="{html.escape(fig.title)}" src="data:image/png;base64,{data}">'
        f"<figcaption>{html.escape(fig.caption)}</figcaption></figure>"
    )


def render_report(content: ReportContent) -> str:
    """The whole report as one HTML string (no external resources)."""
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>{html.escape(content.title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{html.escape(content.title)}</h1>",
    ]
    if content.summary:
        parts.append(f"<p>{html.escape(content.summary)}</p>")
    if content.claims:
        statuses = [claim_status(c) for c in content.claims.values()]
        n = {s: statuses.count(s) for s in (PASS, FAIL, NOT_EVALUATED)}
        head = f"Claims ({n[PASS]} of {len(statuses)} pass"
        head += f", {n[FAIL]} fail" if n[FAIL] else ""
        head += f", {n[NOT_EVALUATED]} not evaluated" if n[NOT_EVALUATED] else ""
        parts.append(f"<h2>{head})</h2>")
        parts.append(claims_table_html(content.claims))
        parts.append(
            '<p class="small">verdict: PASS = the simulation shows the claim and the real '
            "logs, where evaluated, do not contradict it; FAIL = an evaluated side "
            "contradicts it; not evaluated = the simulation could not be evaluated (the "
            "reason is in the claim's note). The machine-readable table is claims.json "
            '("status").</p>'
        )
    if content.notes:
        parts.append("<h2>How to read this</h2><ul>")
        parts.extend(f"<li>{html.escape(n)}</li>" for n in content.notes)
        parts.append("</ul>")
    if content.tables:
        parts.append("<h2>Tables</h2>")
        parts.extend(table_html(t) for t in content.tables)
    if content.figures:
        parts.append("<h2>Figures</h2>")
        parts.extend(figure_html(f) for f in content.figures)
    if content.links:
        parts.append("<h2>Files</h2><ul>")
        parts.extend(
            f'<li><a href="{html.escape(href)}">{html.escape(text)}</a></li>'
            for text, href in content.links
        )
        parts.append("</ul>")
    if content.stages:
        parts.append("<h2>Stages</h2>")
        rows = [
            [
                s.get("name"),
                s.get("status") or ("ok" if s.get("ok") else "failed"),
                s.get("wall_s"),
                s.get("error") or "",
            ]
            for s in content.stages
        ]
        parts.append(
            table_html(
                ReportTable(
                    "Pipeline stages",
                    ["stage", "status", "wall time [s]", "note"],
                    rows,
                )
            )
        )
    if content.metadata:
        parts.append('<h2>Run</h2><div class="tablewrap"><table>')
        parts.extend(
            f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(format_value(v))}</td></tr>"
            for k, v in content.metadata.items()
        )
        parts.append("</table></div>")
    parts.append("</body></html>")
    return "\n".join(parts)


def write_report(content: ReportContent, path: str | os.PathLike) -> Path:
    """Writes the report; returns its path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(render_report(content), encoding="utf-8")
    return path


def load_claims(path: str | os.PathLike) -> dict:
    """Reads a claims.json."""
    return json.loads(Path(path).read_text(encoding="utf-8"))


__all__ = [
    "ReportContent",
    "ReportFigure",
    "ReportTable",
    "claims_table_html",
    "format_value",
    "load_claims",
    "render_report",
    "write_report",
]
