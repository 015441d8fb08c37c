"""``vic-drake compare-online``: its checks before any scan, its JSON, and a
short scan through the command line."""

import json
import os

import pytest

from tests.experiments.fake_scores import fake_scores
from vic_drake.cli import main
from vic_drake.experiments import online_compare, online_sweep, online_sweep_scans
from vic_drake.experiments.online_compare import DITHER_HZ


@pytest.mark.parametrize(
    "args, message",
    [
        (["true_map", "--dither-hz", "2.9", "60"], "--dither-hz 60.0: "),
        (
            ["true_map", "--dither-hz", "3", "3"],
            "--dither-hz 3 3: 3 Hz given twice; give each frequency once",
        ),
        (["wrong_map"], "unknown runs ['wrong_map']; choose from ['true_map'"),
        (["--against", "nope"], "unknown runs ['nope']"),
        (["--duration", "0"], "--duration must be > 0 s; got 0.0"),
        (["--duration", "1e6"], "--duration 1e+06 s is far beyond the scenario"),
        (["--force-min-z", "3"], "--force-min-z 3.0: "),
    ],
)
def test_a_bad_comparison_is_refused_before_any_scan(
    args, message, capsys, monkeypatch
):
    def no_scan(*_args, **_kwargs):
        raise AssertionError("a scan ran")

    monkeypatch.setattr(online_compare, "online_comparison", no_scan)
    assert main(["compare-online", "nominal_vs_vf_synthetic", *args]) == 2
    err = capsys.readouterr().err
    assert f"vic-drake: error: {message}" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "args, message",
    [
        (["--workers", "0"], "argument --workers: takes an integer >= 1; got '0'"),
        (["--workers", "two"], "argument --workers: takes an integer >= 1; got 'two'"),
        (["--scheduler", " "], "argument --scheduler: needs an address such as tcp://"),
        (
            ["--workers", "2", "--scheduler", "tcp://h:8786"],
            "not allowed with argument",
        ),
    ],
)
def test_a_bad_cluster_is_refused_as_the_options_are_read(args, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["compare-online", "nominal_vs_vf_synthetic", *args])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_a_scenario_of_another_controller_is_refused(capsys):
    assert main(["compare-online", "nominal_cs_synthetic", "true_map"]) == 2
    err = capsys.readouterr().err
    assert "runs controller 'cs'; the comparison needs a VS-VF scenario" in err


def test_a_misspelt_scenario_names_the_shipped_ones(capsys):
    assert main(["compare-online", "nominal_vs_vf_synthetc", "true_map"]) == 2
    assert (
        "did you mean diagrams/nominal_vs_vf_synthetic.yaml" in capsys.readouterr().err
    )


def test_the_json_counts_wins_per_frequency(capsys, monkeypatch):
    def fake(base, *, phantom, runs, duration_s, progress, dither_hz):
        rmse = {"wrong_map_+30_dither": 0.68, "online_dither_tracker": dither_hz / 5}
        return {runs[0]: fake_scores(rmse[runs[0]])}

    def in_this_process(jobs, workers, scheduler, on_scan):
        assert (workers, scheduler) == (os.cpu_count(), None)
        scores = []
        for job in jobs:
            scores.append(online_sweep_scans.comparison_scan(job))
            on_scan(job.run, job.dither_hz)
        return scores

    monkeypatch.setattr(online_compare, "online_comparison", fake)
    # Four scans: on a local cluster of the machine's cores, here faked.
    monkeypatch.setattr(online_sweep, "run_on_cluster", in_this_process)
    argv = ["compare-online", "nominal_vs_vf_synthetic", "online_dither_tracker",
            "--dither-hz", "2.9", "3.5", "--against", "wrong_map_+30_dither", "--json"]  # fmt: skip
    assert main(argv) == 0
    out, err = capsys.readouterr()
    result = json.loads(out)
    assert (
        result["dither_hz"] == [2.9, 3.5]
        and result["against"] == "wrong_map_+30_dither"
    )
    assert [
        s["force_rmse_true_N"] for s in result["scores"]["online_dither_tracker"]
    ] == [
        0.58,
        0.7,
    ]
    assert result["wins"] == {
        "online_dither_tracker": {"force_rmse_true_N": 1, "rib_p99_force_N": 0, "of": 2}
    }
    assert f"4 scans on a local cluster of {os.cpu_count()} worker processes" in err
    assert "scan 4 of 4 done: wrong_map_+30_dither at 3.5 Hz" in err


def test_a_short_comparison_runs_through_the_command_line(capsys):
    argv = [
        "compare-online",
        "nominal_vs_vf_synthetic",
        "true_map",
        "--duration",
        "1.0",
    ]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].startswith("| run | force RMSE vs truth N |")
    assert out.splitlines()[2].startswith("| true_map | ")
    # A second of scan holds no scan window and no rib: the nans say so.
    assert "nan scores (true_map): no scan window in what was simulated" in out
    assert "nan p99 force on ribs (true_map): the scan window passed over no rib" in out
    # The table's terms are explained under it, a line each.
    from vic_drake.experiments.online_compare import _COLUMNS

    for _, title, _, _ in _COLUMNS:
        assert f"\n- {title}: " in out
    assert "- vs dithered truth N: the same against the true reference" in out


def test_the_help_says_the_default_frequency():
    from vic_drake.cli import build_parser, subcommand_parser

    text = subcommand_parser(build_parser(), "compare-online").format_help()
    assert f"default {DITHER_HZ}" in text and "--against RUN" in text
