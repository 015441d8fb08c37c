"""A run writes through a marker: a partial or stale run never looks complete."""

import json

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.reproduce import STAGE_NAMES
from vic_drake.reproduce.run_dir import finish_run_dir, prepare_run_dir, work_dir_for


def _marker(folder):
    return json.loads((folder / "run.json").read_text())


def test_run_is_moved_to_out_only_when_finished(tmp_path):
    out = tmp_path / "quick"
    work = prepare_run_dir(out)
    assert work == work_dir_for(out.resolve()) and not out.exists()
    assert _marker(work)["complete"] is False
    (work / "report.html").write_text("first")
    finish_run_dir(work, out, wall_s=1.0)
    assert _marker(out)["complete"] is True and not work.exists()
    # A second run that is interrupted leaves the first one whole.
    work = prepare_run_dir(out)
    (work / "fig.png").write_text("new figure")
    assert (out / "report.html").read_text() == "first"
    assert not (out / "fig.png").exists() and _marker(out)["complete"] is True
    assert _marker(work)["complete"] is False
    # The next run clears the partial one; a finished run replaces the old.
    work = prepare_run_dir(out)
    assert not (work / "fig.png").exists()
    (work / "claims.json").write_text("{}")
    finish_run_dir(work, out)
    assert sorted(p.name for p in out.iterdir()) == ["claims.json", "run.json"]


def test_out_checks_before_any_work(tmp_path):
    other = tmp_path / "mine"
    other.mkdir()
    (other / "thesis.tex").write_text("x")
    with pytest.raises(
        VicDrakeError,
        match=r"holds other files \(thesis.tex\), not a reproduce run; give a new",
    ):
        prepare_run_dir(other)
    afile = tmp_path / "afile"
    afile.write_text("x")
    with pytest.raises(VicDrakeError, match="is a file"):
        prepare_run_dir(afile)
    with pytest.raises(VicDrakeError, match="is a file"):
        prepare_run_dir(afile / "sub")


def test_reproduce_into_a_previous_run_replaces_it(tmp_path):
    from vic_drake.cli import main

    out = tmp_path / "run"
    args = ["reproduce", "--stages", "claims", "--out", str(out), "--quiet"]
    assert main([*args, "--allow-fail"]) == 0
    (out / "stale.png").write_text("from an older run")
    # Not every claim passes (none was evaluated): exit status 1.
    assert main(args) == 1
    assert not (out / "stale.png").exists()
    marker = _marker(out)
    assert marker["complete"] is True
    assert set(marker["claims"].values()) == {"not evaluated"}


def test_a_running_run_is_not_clobbered(tmp_path):
    """A second run into the same folder while the first is writing is refused."""
    import subprocess
    import sys

    out = tmp_path / "run"
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        work = prepare_run_dir(out)
        marker = _marker(work)
        marker["pid"] = other.pid
        (work / "run.json").write_text(json.dumps(marker))
        with pytest.raises(VicDrakeError, match=f"process {other.pid}"):
            prepare_run_dir(out)
    finally:
        other.kill()
        other.wait()
    assert prepare_run_dir(out).is_dir()  # The writer is gone: cleared.


def _complete_run(out, *, data_dir=None, stages=STAGE_NAMES, legacy=False, quick=True):
    """A finished run in ``out``: report, figures and a marker like reproduce's."""
    work = prepare_run_dir(out)
    (work / "report.html").write_text("the whole run")
    (work / "figures").mkdir()
    (work / "figures" / "fig6.png").write_text("png")
    fields = {"stages": [{"name": n, "ok": True, "status": "ok"} for n in stages]}
    if not legacy:  # Markers before this change did not record the data.
        fields["data_dir"] = data_dir
    finish_run_dir(work, out, quick=quick, **fields)


def test_a_quick_run_does_not_replace_a_full_one(tmp_path):
    """A quick run over a full run would lose the full scans and compare_real."""
    full = tmp_path / "full"
    _complete_run(full, stages=("offline_sim", "claims"), quick=False)
    with pytest.raises(VicDrakeError, match="it is a full run and this one is quick"):
        prepare_run_dir(full, quick=True)
    assert (full / "report.html").read_text() == "the whole run"
    # A full run replaces it, and so does a quick one with overwrite.
    assert prepare_run_dir(full, quick=True, overwrite=True).is_dir()
    assert prepare_run_dir(full).is_dir()
    # A quick run replaces a quick run.
    quick = tmp_path / "quick"
    _complete_run(quick, stages=("offline_sim", "claims"))
    assert prepare_run_dir(quick, quick=True).is_dir()


@pytest.fixture
def no_data(monkeypatch, tmp_path):
    """No data folder: neither $VIC_DRAKE_DATA nor the default lookup."""
    import vic_drake.paths

    monkeypatch.delenv("VIC_DRAKE_DATA", raising=False)
    monkeypatch.setattr(vic_drake.paths, "DEFAULT_DATA_DIR", tmp_path / "no-data")


def test_a_stage_subset_does_not_replace_a_complete_run(tmp_path, capsys, no_data):
    """Issue: `reproduce --stages claims` into a complete run left only
    claims.json and run.json (report, logs and figures gone)."""
    from vic_drake.cli import main

    out = tmp_path / "quick"
    _complete_run(out)
    args = ["reproduce", "--stages", "claims", "--out", str(out), "--quiet"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "holds a complete run that this one does not cover" in err
    assert "offline_sim" in err and "--stages claims" in err
    assert "another --out" in err and "--overwrite" in err
    assert (out / "report.html").read_text() == "the whole run"
    assert (out / "figures" / "fig6.png").is_file()
    assert not work_dir_for(out.resolve()).exists()  # Refused before any work.
    # Asked for: the partial run replaces the whole one.
    assert main([*args, "--overwrite"]) == 1
    assert sorted(p.name for p in out.iterdir()) == ["claims.json", "run.json"]
    # A run of the same stages (or more) covers it: no --overwrite needed.
    assert main(args) == 1
    assert main(["reproduce", "--stages", "claims,report", "--out", str(out)]) == 1


def test_a_run_without_data_does_not_replace_one_with_data(tmp_path, no_data, capsys):
    """Issue: a run without the data silently replaced one made with it."""
    from vic_drake.cli import main

    made = tmp_path / "made_with_data"
    _complete_run(made, legacy=True, stages=("offline_real", "claims"))
    args = ["reproduce", "--stages", "offline_real,claims", "--out", str(made)]
    assert main(args) == 2
    assert "made with the paper's data" in capsys.readouterr().err
    assert (made / "report.html").read_text() == "the whole run"
    data = tmp_path / "data"
    out = tmp_path / "real"
    _complete_run(out, data_dir=str(data), stages=("claims",))
    with pytest.raises(VicDrakeError, match="made with the paper's data and this run"):
        prepare_run_dir(out, stages=("claims",), data_dir=None)
    assert (out / "report.html").is_file()
    # With the data (any folder) it is replaced; so it is with overwrite.
    assert prepare_run_dir(out, stages=("claims",), data_dir=data).is_dir()
    assert prepare_run_dir(out, stages=("claims",), overwrite=True).is_dir()
    # A marker from before the data was recorded: a data stage that ran
    # says it had the data.
    legacy = tmp_path / "legacy"
    _complete_run(legacy, legacy=True)
    with pytest.raises(VicDrakeError, match="made with the paper's data"):
        prepare_run_dir(legacy)
    no_data_run = tmp_path / "synthetic"
    _complete_run(no_data_run, legacy=True, stages=("offline_sim", "claims"))
    assert prepare_run_dir(no_data_run).is_dir()


def test_reproduce_records_its_data_folder(tmp_path, no_data):
    from vic_drake.reproduce import ReproduceOptions, reproduce

    out = tmp_path / "run"
    reproduce(ReproduceOptions(out_dir=out, stages=("claims",)))
    assert _marker(out)["data_dir"] is None
