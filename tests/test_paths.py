"""Data, input and output paths: one error for a bad --data-dir or $VIC_DRAKE_DATA,
and output paths checked before any simulation."""

from pathlib import Path

import pytest

from vic_drake.cli import main
from vic_drake.errors import VicDrakeError
from vic_drake.paths import (
    CAMPAIGN_SPEC_FILE,
    REPRODUCE_RUN_FILE,
    check_data_dir,
    check_input_file,
    check_output_dir,
    check_output_file,
    check_run_folder,
    find_bag,
)


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
    # (The package's compare_real is its module; the command imports the
    # function from there.)
    monkeypatch.setattr(
        "vic_drake.experiments.compare_real.compare_real", no_simulation
    )
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


def test_find_bag_as_given_then_in_the_data_folder(tmp_path, monkeypatch):
    data = tmp_path / "data"
    (data / "palpation" / "soft").mkdir(parents=True)
    here = tmp_path / "here"
    (here / "palpation" / "soft").mkdir(parents=True)
    monkeypatch.delenv("VIC_DRAKE_DATA", raising=False)
    monkeypatch.chdir(here)
    # The current folder first, then the data folder.
    assert find_bag("palpation/soft", data) == Path("palpation/soft")
    monkeypatch.chdir(tmp_path)
    assert find_bag("palpation/soft", data) == data / "palpation" / "soft"
    monkeypatch.setenv("VIC_DRAKE_DATA", str(data))
    assert find_bag("palpation/soft") == data / "palpation" / "soft"
    assert find_bag(here / "palpation" / "soft") == here / "palpation" / "soft"
    with pytest.raises(VicDrakeError) as exc:
        find_bag("palpation/sotf", what="palpation bag", expected="a palpation")
    assert str(exc.value) == (
        f"palpation bag 'palpation/sotf' does not exist in the current folder "
        f"({str(tmp_path)!r}) nor in the data folder {str(data)!r} "
        "($VIC_DRAKE_DATA) (did you mean 'palpation/soft'?); expected a palpation"
    )
    # An absolute path is only itself.
    with pytest.raises(VicDrakeError, match=r"'/.*sotf' does not exist \(did you"):
        find_bag(data / "palpation" / "sotf")


def test_check_input_file_names_a_folder_and_an_example(tmp_path):
    (tmp_path / "b.yaml").write_text("")
    (tmp_path / "a.yaml").write_text("")
    assert check_input_file(tmp_path / "a.yaml", "scenario file") == tmp_path / "a.yaml"
    with pytest.raises(VicDrakeError) as exc:
        check_input_file(tmp_path, "scenario file")
    assert str(exc.value) == (
        f"scenario file {str(tmp_path)!r} is a folder; give one of its .yaml files, "
        f"e.g. {tmp_path / 'a.yaml'}"
    )
    (tmp_path / "empty").mkdir()
    with pytest.raises(VicDrakeError, match="folder .with no .yaml files"):
        check_input_file(tmp_path / "empty", "scenario file")
    with pytest.raises(VicDrakeError, match=r"does not exist \(did you mean"):
        check_input_file(tmp_path / "c.yaml", "scenario file")


def test_a_run_folder_is_new_empty_or_its_own_kind(tmp_path):
    new, empty = tmp_path / "new", tmp_path / "empty"
    empty.mkdir()
    for marker in (REPRODUCE_RUN_FILE, CAMPAIGN_SPEC_FILE):
        assert check_run_folder(new, marker, others="x") is False
        assert check_run_folder(empty, marker, others="x") is False
    assert not new.exists()  # Nothing is written.
    run, campaign = tmp_path / "run", tmp_path / "campaign"
    for folder, marker in ((run, REPRODUCE_RUN_FILE), (campaign, CAMPAIGN_SPEC_FILE)):
        folder.mkdir()
        (folder / marker).write_text("")
        assert check_run_folder(folder, marker, others="x") is True
    # Each command's folder is named when the other command is given it.
    with pytest.raises(
        VicDrakeError,
        match=r"holds a vic-drake campaign \(spec.yaml\), not a reproduce run; "
        r"give a new or empty folder, or a previous run's folder$",
    ):
        check_run_folder(campaign, REPRODUCE_RUN_FILE, others="a previous run's folder")
    with pytest.raises(
        VicDrakeError,
        match=r"holds a vic-drake reproduce run \(run.json\), not a campaign",
    ):
        check_run_folder(run, CAMPAIGN_SPEC_FILE, others="x")
    (empty / "a").write_text("")
    (empty / "b").mkdir()
    for name in "cdef":
        (empty / name).write_text("")
    with pytest.raises(
        VicDrakeError, match=r"holds other files \(a, b/, c, d, \.\.\.\)"
    ):
        check_run_folder(empty, CAMPAIGN_SPEC_FILE, others="x")
    with pytest.raises(VicDrakeError, match="is a file; give a folder"):
        check_run_folder(empty / "a", CAMPAIGN_SPEC_FILE, others="x")
