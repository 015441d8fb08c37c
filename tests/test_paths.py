"""Data and output paths: one error for a bad --data-dir or $VIC_DRAKE_DATA,
and output paths checked before any simulation."""

import pytest

from vic_drake.cli import main
from vic_drake.errors import VicDrakeError
from vic_drake.paths import check_data_dir, check_output_dir, check_output_file


def test_bad_env_data_dir_is_the_bad_option_error(tmp_path, monkeypatch, capsys):
    missing = tmp_path / "nothing"
    monkeypatch.setenv("VIC_DRAKE_DATA", str(missing))
    with pytest.raises(VicDrakeError, match="VIC_DRAKE_DATA=.*does not exist"):
        check_data_dir()
    monkeypatch.delenv("VIC_DRAKE_DATA")
    with pytest.raises(VicDrakeError, match="--data-dir .*does not exist"):
        check_data_dir(missing)
    missing.mkdir()
    with pytest.raises(VicDrakeError, match="does not hold the paper's data"):
        check_data_dir(missing)
    # Every command: exit 2 with the message, before any work.
    monkeypatch.setenv("VIC_DRAKE_DATA", str(tmp_path / "nothing_either"))
    assert main(["reproduce", "--quick", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "VIC_DRAKE_DATA=" in err and "synthetic phantom" in err
    assert not (tmp_path / "o").exists()


def test_output_paths_checked_before_simulating(tmp_path, monkeypatch, capsys):
    import vic_drake.experiments as experiments

    def no_simulation(*args, **kwargs):
        raise AssertionError("simulated before checking the output path")

    monkeypatch.setattr(experiments, "run_scan", no_simulation)
    monkeypatch.setattr(experiments, "compare_real", no_simulation)
    afile = tmp_path / "afile"
    afile.write_text("x")
    scenario = "diagrams/nominal_vs_vf_synthetic.yaml"
    cases = [
        ["scan", scenario, "--out", str(afile / "log.parquet")],
        ["scan", scenario, "--out", str(tmp_path / "log.txt")],
        ["compare-real", "experiments/x", "--plot", str(afile / "p.png")],
        ["compare-real", "experiments/x", "--out", str(afile / "l.csv")],
        ["map", "--out", str(afile / "m")],
        ["reproduce", "--quick", "--out", str(afile)],
        ["fit-palpation", "palpation/x", "--plot", str(afile / "p.png")],
        ["load-test", "l", "--fit-from", "p", "--plot", str(tmp_path / "p.xyz")],
    ]
    for argv in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("vic-drake: error: --") and "Traceback" not in err, err


def test_check_output_helpers(tmp_path):
    d = check_output_dir(tmp_path / "a" / "b")
    assert d.is_dir()
    f = check_output_file(tmp_path / "c" / "x.png", "--plot", (".png",))
    assert f.parent.is_dir() and not f.exists()
    with pytest.raises(VicDrakeError, match="is a folder"):
        check_output_file(d, "--plot")
