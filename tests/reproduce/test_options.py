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
