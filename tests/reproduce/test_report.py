"""The HTML report is self-contained and shows every claim's verdict."""

import base64
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from vic_drake.reproduce.report import (  # noqa: E402
    ReportContent,
    ReportFigure,
    ReportTable,
    format_value,
    render_report,
    write_report,
)
from vic_drake.reproduce.stages.claims import _TABLE_COLUMNS


def _content():
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    claims = {
        "C1": {
            "statement": "HC beats KV",
            "paper": {"kv": 0.066},
            "sim": {"kv": 0.07},
            "real": None,
            "pass": True,
            "pass_sim": True,
            "pass_real": None,
            "detail": "why <b>",
        },
        "C2": {
            "statement": "decays",
            "paper": "exp",
            "sim": None,
            "real": None,
            "pass": False,
            "pass_sim": None,
            "pass_real": None,
            "detail": "no data",
        },
        "C3": {
            "statement": "ribs",
            "paper": "4 ribs",
            "sim": {"n_ribs": 2},
            "real": None,
            "pass": False,
            "pass_sim": False,
            "pass_real": None,
            "detail": "",
        },
    }
    return ReportContent(
        claims=claims,
        figures=[ReportFigure("Fig. 2", "load test", fig)],
        tables=[ReportTable("Table I", ["model", "residual"], [["KV", 0.066]])],
        metadata={"drake": "1.51.1"},
        stages=[{"name": "offline", "ok": True, "wall_s": 1.2, "error": None}],
        links=[("replay", "replay.html")],
    )


def test_report_is_self_contained_and_escapes(tmp_path):
    path = write_report(_content(), tmp_path / "r" / "report.html")
    text = path.read_text()
    assert "Claims (1 of 3 pass, 1 fail, 1 not evaluated)" in text
    assert text.count('class="pass"') == 2
    # The claim that was not evaluated says so; only C3 is a FAIL.
    assert text.count(">FAIL<") == 2  # C3's sim verdict and its overall verdict
    assert '<td class="ne">not evaluated</td>' in text
    assert "why &lt;b&gt;" in text  # detail escaped
    # No external resources: every img is inline data, no scripts or stylesheets fetched.
    assert not re.search(r'src="(?!data:)', text)
    assert "<link" not in text and "<script" not in text
    png = re.search(r'src="data:image/png;base64,([^"]+)"', text).group(1)
    assert base64.b64decode(png)[:8] == b"\x89PNG\r\n\x1a\n"


def test_format_value():
    assert format_value(None) == "—"
    assert format_value(True) == "yes"
    assert format_value(0.0123456) == "0.01235"
    assert format_value({"a": 1, "b": [1.5, None]}) == "a: 1\nb: [1.5, —]"
    assert "n/a" in format_value(float("nan"))
    assert (
        format_value({"log": {"a": 1, "b": 2}, "c": 3}) == "log:\n  a: 1\n  b: 2\nc: 3"
    )


def test_render_without_claims():
    text = render_report(ReportContent(title="t"))
    assert "<h1>t</h1>" in text and "Claims" not in text


def _wide_content():
    """A report like a run's: the 12-column scan-metrics table, long claims."""
    content = _content()
    keys = [name for _, name, _ in _TABLE_COLUMNS]
    rows = [
        ["disturbance", c, *(123.456789 * (i + 1) for i in range(len(keys)))]
        for c in ("cs", "cf", "vs-cf", "vs-vf")
    ]
    content.tables.append(
        ReportTable(
            "Simulated scans: metrics", ["condition", "controller", *keys], rows
        )
    )
    content.claims["C1"]["sim"] = {
        "a_rather_long_metric_name_without_spaces_" * 3: 0.123456,
        "per_log": {"test_soft_25hz_and_more": 0.5, "x" * 90: 1.0},
    }
    return content


def test_report_fits_a_1400_px_browser(tmp_path):
    """In headless Chromium at 1400 px the page does not scroll sideways:
    every table fits or scrolls inside its own box."""
    from tests.browser import chromium, dump_dom, screenshot

    chromium()
    page = tmp_path / "report.html"
    write_report(_wide_content(), page)
    probe = tmp_path / "probe.html"
    probe.write_text(
        page.read_text().replace(
            "</body>",
            "<script>const w=document.documentElement.scrollWidth;"
            "const bad=[...document.querySelectorAll('table')].filter(t=>{"
            "const box=t.parentElement;const r=box.getBoundingClientRect();"
            "return r.right>window.innerWidth+1||(t.scrollWidth>box.clientWidth+1&&"
            "getComputedStyle(box).overflowX!=='auto');}).length;"
            "document.body.insertAdjacentHTML('beforeend',"
            "`<p id=probe>width=${w} inner=${window.innerWidth} bad=${bad}</p>`);"
            "</script></body>",
        )
    )
    dom = dump_dom(probe, width=1400)
    found = re.search(r"width=(\d+) inner=(\d+) bad=(\d+)", dom)
    assert found, dom[-500:]
    width, inner, bad = map(int, found.groups())
    assert inner == 1400 and width <= inner and bad == 0, found.group(0)
    img = screenshot(page, tmp_path / "report.png", width=1400, height=1000)
    assert img.shape[1] == 1400 and (img.sum(axis=-1) < 200).mean() > 0.001
