"""Reproduction options: bad stages, phantoms and data folders are clean errors."""

import pytest

from vic_drake.cli import main
from vic_drake.errors import VicDrakeError
from vic_drake.reproduce import ReproduceOptions


def test_options_reject_unknown_stage(tmp_path):
    with pytest.raises(VicDrakeError, match="unknown stage"):
        ReproduceOptions(out_dir=tmp_path, stages=("nope",))
    with pytest.raises(VicDrakeError, match="phantom"):
        ReproduceOptions(out_dir=tmp_path, phantom="jelly")


def test_options_reject_a_data_dir_without_data(tmp_path):
    with pytest.raises(VicDrakeError, match="does not hold the paper's data"):
        ReproduceOptions(out_dir=tmp_path / "out", data_dir=tmp_path)


def test_cli_unknown_stage_is_a_clean_error(tmp_path, capsys):
    assert main(["reproduce", "--out", str(tmp_path), "--stages", "bogus"]) == 2
    assert "unknown stage" in capsys.readouterr().err


def test_options_take_a_relaxation_and_reject_anything_else(tmp_path):
    from vic_drake.tissue import RelaxationParams

    rel = RelaxationParams((0.03, 0.09), (1.7, 65.0))
    assert ReproduceOptions(out_dir=tmp_path, relaxation=rel).relaxation is rel
    assert ReproduceOptions(out_dir=tmp_path).relaxation is None
    with pytest.raises(VicDrakeError, match="relaxation must be"):
        ReproduceOptions(out_dir=tmp_path, relaxation=(0.03, 1.7))


def test_cli_bad_relaxation_is_a_clean_error(tmp_path, capsys):
    argv = ["reproduce", "--out", str(tmp_path), "--relaxation", "0.3:-1"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--relaxation takes G:TAU pairs" in err and "Traceback" not in err


def test_an_empty_stage_list_is_an_error_naming_the_stages(
    tmp_path, capsys, monkeypatch
):
    """Issue: `--stages ""` ran every stage."""
    import vic_drake.reproduce.pipeline as pipeline
    from vic_drake.reproduce import STAGE_NAMES

    with pytest.raises(VicDrakeError, match="no stage given") as err:
        ReproduceOptions(out_dir=tmp_path, stages=())
    assert all(name in str(err.value) for name in STAGE_NAMES)
    ran = []
    monkeypatch.setattr(
        pipeline,
        "STAGES",
        tuple((n, lambda ctx, n=n: ran.append(n)) for n in STAGE_NAMES),
    )
    for empty in ("", " , "):
        out = tmp_path / "out"
        assert main(["reproduce", "--out", str(out), "--stages", empty]) == 2
        err = capsys.readouterr().err
        assert "no stage given" in err and "offline_real, offline_sim" in err
        assert not ran and not out.exists()


def test_stage_names_are_the_pipelines():
    from vic_drake.reproduce import STAGE_NAMES, STAGES

    assert tuple(name for name, _ in STAGES) == STAGE_NAMES


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"workers": 0}, "workers must be an integer >= 1 or None; got 0"),
        ({"workers": True}, "workers must be an integer >= 1"),
        ({"workers": 1.5}, "workers must be an integer >= 1"),
        ({"scheduler": " "}, "scheduler must be an address such as tcp://"),
        ({"workers": 2, "scheduler": "tcp://h:8786"}, "not both"),
    ],
)
def test_options_reject_bad_cluster_settings(tmp_path, kwargs, message):
    with pytest.raises(VicDrakeError, match=message):
        ReproduceOptions(out_dir=tmp_path, **kwargs)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--workers", "0"], "argument --workers: takes an integer >= 1"),
        (
            ["--workers", "2", "--scheduler", "tcp://h:8786"],
            "argument --scheduler: not allowed with argument --workers",
        ),
    ],
)
def test_cli_bad_cluster_arguments_are_clean_errors(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", "--out", str(tmp_path / "out"), *argv])
    assert exc.value.code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
