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


def _help(capsys) -> str:
    with pytest.raises(SystemExit):
        build_parser().parse_args(["reproduce", "--help"])
    return " ".join(capsys.readouterr().out.split())


def test_help_names_the_stages_and_the_quick_runs_time(capsys):
    from vic_drake.reproduce import STAGE_NAMES

    text = _help(capsys).split("options:", 1)[1]
    stages_help = text.split("--stages LIST", 1)[1].split("--overwrite", 1)[0]
    for name in STAGE_NAMES:
        assert name in stages_help, name
    quick_help = text.split("--quick", 1)[1].split("--phantom", 1)[0]
    assert "5 minutes" not in quick_help and "half a minute" in quick_help
    assert "--overwrite" in text


def test_claim_lines_give_the_reason_of_a_fail():
    """Issue: the console printed "C2: FAIL" with no reason (only in the report)."""
    from vic_drake.commands.reproduce import _claim_line

    curve = {"tau_s": 7.4, "a": 0.15, "c": 0.03, "spearman": -1.0, "n_points": 48}
    c2 = {
        "statement": "The fit residual falls about exponentially",
        "sim": {"sim_2.5hz": {**curve, "r2": 0.99, "ratio_last_first": 0.61}},
        "real": {
            "test_soft_1hz": {
                **curve,
                "r2": 0.97,
                "ratio_last_first": 0.13,
                "pass": True,
            },
            "test_soft_25hz": {
                **curve,
                "r2": 0.257,
                "spearman": -0.81,
                "ratio_last_first": 0.26,
                "pass": False,
            },
        },
        "pass": False,
        "status": "fail",
        "pass_sim": True,
        "pass_real": False,
        "detail": "fit r(T)=c+a exp(-T/tau); pass: spearman <= -0.8, R^2 >= 0.9",
    }
    line = _claim_line("C2", c2)
    assert "FAIL" in line
    assert "real logs: test_soft_25hz misses R^2 0.26 (needs >= 0.9)" in line
    assert "test_soft_1hz" not in line and "simulation" not in line
    # A flat side: its values and the claim's pass criterion.
    c4 = {
        "statement": "VS-CF tracks its force reference about as well as CF",
        "sim": {"rmse_ratio": 1.35, "vs_cf_lifted_off": True},
        "real": None,
        "pass": False,
        "status": "fail",
        "pass_sim": False,
        "pass_real": None,
        "detail": "RMSE of pressing force; pass: ratio <= 1.2",
    }
    line = _claim_line("C4", c4)
    assert (
        "(simulation: rmse_ratio 1.35, vs_cf_lifted_off true; pass: ratio <= 1.2)"
        in line
    )
    # Failed checks are named.
    c7 = {**c4, "sim": {"tank_min_J": 0.3, "checks": {"tank_above_min": False}}}
    assert "check(s) tank_above_min fail" in _claim_line("C7", c7)
