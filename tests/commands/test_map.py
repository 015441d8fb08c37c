"""``vic-drake map``: the metrics contract, outputs and bad input."""

import json

import numpy as np
import pytest

from vic_drake.cli import main
from vic_drake.commands.mapping import METRIC_KEYS

SMALL = ["--region=-0.09,-0.06,-0.37,-0.35", "--resolution-mm", "1"]


def test_map_json_contract_and_outputs(tmp_path, capsys):
    out = tmp_path / "map"
    status = main(
        ["map", "--phantom", "synthetic", "--out", str(out), "--json", *SMALL]
    )
    captured = capsys.readouterr()
    assert status == 0
    result = json.loads(captured.out)  # stdout holds the JSON alone
    assert tuple(result) == METRIC_KEYS
    assert json.loads((out / "metrics.json").read_text()) == result
    assert result["points"] == 12
    for key in ("kappa_rmse_pct", "lambda_rmse_pct", "surface_rmse_mm", "wall_s"):
        assert isinstance(result[key], float) and result[key] >= 0
    assert result["kappa_rmse_pct"] < 10.0
    assert result["surface_rmse_mm"] < 0.5
    assert all(isinstance(v, float) for v in result["ribs_true"] + result["ribs_found"])
    maps = np.load(out / "maps.npz")
    for key in ("x", "y", "surface", "kappa", "lambda", "kappa_std", "lambda_std"):
        assert key in maps
    assert maps["kappa"].shape == (maps["x"].size, maps["y"].size) == (31, 21)
    for name in (
        "fig4_stiffness_damping.png",
        "fig5_surface_kappa.png",
        "gp_std.png",
        "map_vs_truth.png",
        "points.csv",
    ):
        assert (out / name).stat().st_size > 0
    assert "[vic-drake]" in captured.err  # progress goes to stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["--resolution-mm", "-1"], "--resolution-mm"),
        (["--resolution-mm", "nan"], "--resolution-mm"),
        (["--spacing-cm", "0"], "--spacing-cm"),
        (["--region", "1,2,3"], "--region"),
        (["--region", "0.1,0.0,-0.4,-0.3"], "--region"),
        (["--resolution-mm", "0.001"], "map grid would have"),
        (["--region=-0.09,-0.085,-0.37,-0.365"], "at least 4"),
        (["--seed", "-5"], "--seed must be an integer >= 0; got -5"),
    ],
)
def test_bad_input_exits_2(tmp_path, capsys, args, message):
    status = main(["map", "--out", str(tmp_path / "o"), *args])
    assert status == 2
    err = capsys.readouterr().err
    assert "vic-drake: error:" in err and message in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()  # Refused before the folder is made.


@pytest.mark.parametrize("marker", ["run.json", "spec.yaml"])
def test_out_that_holds_another_run_exits_2(tmp_path, capsys, marker):
    (tmp_path / marker).write_text("{}")
    assert main(["map", "--out", str(tmp_path), *SMALL]) == 2
    assert "holds a vic-drake" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == [marker]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--workers", "0"], "argument --workers: takes an integer >= 1; got '0'"),
        (
            ["--workers", "2", "--scheduler", "tcp://h:8786"],
            "argument --scheduler: not allowed with argument --workers",
        ),
    ],
)
def test_a_bad_cluster_is_refused_as_the_options_are_read(
    tmp_path, capsys, args, message
):
    with pytest.raises(SystemExit) as exc:
        main(["map", "--out", str(tmp_path / "o"), *args])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_the_palpations_run_in_this_process_by_default():
    from vic_drake.cli import build_parser

    args = build_parser().parse_args(["map", "--out", "o"])
    assert (args.workers, args.scheduler) == (1, None)


@pytest.mark.parametrize(
    "option, value", [("--phantom", "cardboard"), ("--kernel", "cubic")]
)
def test_choices_are_argparse_choices(tmp_path, capsys, option, value):
    """--phantom and --kernel list their choices in --help and in the error."""
    from vic_drake.cli import build_parser, subcommand_parser

    text = subcommand_parser(build_parser(), "map").format_help()
    assert "{synthetic,measured}" in text and "{rbf,matern}" in text
    with pytest.raises(SystemExit) as exc:
        main(["map", "--out", str(tmp_path / "o"), option, value])
    assert exc.value.code == 2
    assert f"{option}: invalid choice: {value!r}" in capsys.readouterr().err


def test_choices_are_the_pipelines():
    """The parser's choices, written out, are those the pipeline knows."""
    from vic_drake.commands.mapping import GP_KERNELS, PHANTOMS
    from vic_drake.estimation.gp_fit import KERNELS
    from vic_drake.tissue.phantom import PHANTOM_KINDS

    assert PHANTOMS == PHANTOM_KINDS and GP_KERNELS == KERNELS


def test_measured_without_data_exits_2(tmp_path, capsys):
    status = main(
        [
            "map",
            "--phantom",
            "measured",
            "--data-dir",
            str(tmp_path / "none"),
            "--out",
            str(tmp_path / "o"),
        ]
    )
    assert status == 2
    assert "does not exist" in capsys.readouterr().err


def test_out_that_is_a_file_exits_2(tmp_path, capsys):
    path = tmp_path / "file"
    path.write_text("x")
    assert main(["map", "--out", str(path), *SMALL]) == 2
    assert "is a file" in capsys.readouterr().err


@pytest.mark.realdata
def test_map_of_the_measured_phantom_small_region(data_dir, tmp_path, capsys):
    out = tmp_path / "measured"
    status = main(
        [
            "map",
            "--phantom",
            "measured",
            "--data-dir",
            str(data_dir),
            "--out",
            str(out),
            "--json",
            "--no-figures",
            "--region=-0.12,-0.09,-0.38,-0.36",
            "--resolution-mm",
            "1",
        ]
    )
    assert status == 0
    result = json.loads(capsys.readouterr().out)
    assert tuple(result) == METRIC_KEYS and result["points"] == 12
    assert result["kappa_rmse_pct"] < 10.0
    assert result["surface_rmse_mm"] < 0.5
    # The rib near x = -10.6 cm of the measured map is found within 2 mm.
    assert len(result["ribs_true"]) == len(result["ribs_found"]) == 1
    assert result["ribs_found"][0] == pytest.approx(result["ribs_true"][0], abs=2e-3)
