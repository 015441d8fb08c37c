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
    assert "Claims (1 of 2 pass)" in text
    assert text.count('class="pass"') == 2 and 'class="fail">FAIL' in text
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
