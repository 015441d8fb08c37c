"""A run writes through a marker: a partial or stale run never looks complete."""

import json

import pytest

from vic_drake.errors import VicDrakeError
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
    with pytest.raises(VicDrakeError, match="not a vic-drake reproduce run"):
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
