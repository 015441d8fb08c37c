"""``vic-drake reproduce``: exit status, claim lines, the live Meshcat view."""

from types import SimpleNamespace

import pytest

from vic_drake.cli import build_parser


def test_help_documents_exit_status_and_allow_fail(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["reproduce", "--help"])
    text = capsys.readouterr().out
    assert "--allow-fail" in text and "exit status: 0 when every claim" in text
    assert "--meshcat" in text


def test_claim_lines_never_print_fail_for_not_evaluated():
    from vic_drake.commands.reproduce import _claim_line

    line = _claim_line(
        "C6",
        {
            "statement": "VS-VF caps the force",
            "pass": False,
            "status": "not evaluated",
            "pass_sim": None,
            "pass_real": None,
            "detail": "thresholds; sim not evaluated: the probe never crossed a rib",
        },
    )
    assert "NOT EVALUATED" in line and "FAIL" not in line
    assert "the probe never crossed a rib" in line


def test_meshcat_live_view_prints_its_url_and_stops_on_ctrl_c(
    monkeypatch, capsys, caplog
):
    import logging

    import vic_drake.commands.reproduce as cmd
    from vic_drake.reproduce.stages.replay import new_meshcat

    with caplog.at_level(logging.INFO, logger="drake"):
        meshcat = new_meshcat()
    # Drake's "Meshcat listening for connections at http://..." is not logged.
    assert not [r for r in caplog.records if "listening" in r.getMessage()]

    def interrupt(_):
        raise KeyboardInterrupt

    monkeypatch.setattr(cmd.time, "sleep", interrupt)
    cmd._serve_live(SimpleNamespace(results={"replay": {"meshcat": meshcat}}), print)
    err = capsys.readouterr().err
    assert f"live at {meshcat.web_url()}" in err and "Ctrl-C" in err
    assert "Meshcat stopped" in err
