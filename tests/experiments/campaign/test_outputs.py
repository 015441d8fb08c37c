"""A campaign's folder rules and displayed figures, without running a scan.

The folder is checked before any work and made only once the cluster is
reached (a fake cluster that fails stands in for Dask); CS and CF have no
tank, so their tank figures are NaN and show as a dash.
"""

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from vic_drake.commands.campaign import _human
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign import engine, run_campaign, run_metrics
from vic_drake.experiments.campaign.report import summary_html
from vic_drake.experiments.campaign.run import failed_row
from vic_drake.experiments.campaign.spec import CampaignSpec
from vic_drake.experiments.campaign.stats import per_controller

SMOKE = Path(__file__).resolve().parents[3] / "campaigns" / "smoke.yaml"


class _NoCluster(Exception):
    """Raised by the fake cluster: the campaign got as far as connecting."""


@pytest.fixture
def no_cluster(monkeypatch):
    """The cluster cannot be reached, as with an unreachable --scheduler."""

    def fail(workers, scheduler):
        raise _NoCluster

    monkeypatch.setattr(engine, "dask_session", fail)


def _listing(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def _reproduce_run(folder: Path) -> Path:
    (folder / "logs").mkdir(parents=True)
    (folder / "run.json").write_text('{"complete": true}\n')
    (folder / "report.html").write_text("<html></html>")
    return folder


@pytest.mark.parametrize("resume", [True, False])
def test_a_reproduce_run_folder_is_refused_and_left_alone(tmp_path, no_cluster, resume):
    out = _reproduce_run(tmp_path / "quick")
    before = _listing(out)
    with pytest.raises(
        VicDrakeError,
        match=r"holds a vic-drake reproduce run \(run.json\), not a campaign",
    ):
        run_campaign(SMOKE, out, workers=1, resume=resume)
    assert _listing(out) == before


def test_a_folder_of_other_files_is_refused_naming_them(tmp_path, no_cluster):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    (out / "data").mkdir()
    with pytest.raises(
        VicDrakeError, match=r"holds other files \(data/, notes.txt\), not a campaign;"
    ):
        run_campaign(SMOKE, out, workers=1, resume=True)
    assert _listing(out) == ["data", "notes.txt"]


def test_resume_without_a_campaign_says_so_and_starts(tmp_path, no_cluster):
    lines = []
    out = tmp_path / "new"
    with pytest.raises(_NoCluster):  # It went on to start the campaign.
        run_campaign(SMOKE, out, workers=1, resume=True, progress=lines.append)
    assert lines == [
        f"nothing to resume: {str(out)!r} does not exist; starting the campaign"
    ]
    out.mkdir()
    lines.clear()
    with pytest.raises(_NoCluster):
        run_campaign(SMOKE, out, workers=1, resume=True, progress=lines.append)
    assert lines == [f"nothing to resume: {str(out)!r} is empty; starting the campaign"]


def _texts() -> dict:
    """SMOKE's spec and base scenario as a campaign folder stores them."""
    from vic_drake.experiments.campaign.spec import load_campaign_spec
    from vic_drake.paths import CAMPAIGN_SPEC_FILE

    spec, base = load_campaign_spec(SMOKE)
    return {
        CAMPAIGN_SPEC_FILE: engine._spec_text(spec, base),
        engine.CAMPAIGN_BASE_FILE: Path(base).read_text(),
    }


def _stored_campaign(out: Path, codes) -> list[str]:
    """A campaign folder of SMOKE's spec with one stored row per code in
    ``codes`` (None: a row without one); returns the listing."""
    from vic_drake.experiments.campaign.plan import plan_campaign
    from vic_drake.experiments.campaign.spec import load_campaign_spec
    from vic_drake.scenario import load_scenario

    spec, base = load_campaign_spec(SMOKE)
    engine._create(out, _texts())
    plans = plan_campaign(spec, load_scenario(base))
    for plan, code in zip(plans, codes):
        row = failed_row(plan, "a stand-in row", wall_s=0.0)
        row["status"], row["error"] = "ok", ""
        row.pop("code_id")
        if code is not None:
            row["code_id"] = code
        (out / "rows" / f"{plan.run_id}.json").write_text(json.dumps(row))
    return _listing(out)


def test_a_resume_with_other_code_is_refused_before_any_work(tmp_path, no_cluster):
    """Rows another code computed (another source, Drake or Python, or a row
    from before rows carried their code) are not mixed with this code's."""
    from vic_drake.provenance import code_id

    out = tmp_path / "c"
    other = "vic_drake 0.1.0 source 0123456789ab, drake 1.40.0, python 3.10.0"
    before = _stored_campaign(out, [code_id(), other, other, None])
    with pytest.raises(VicDrakeError) as err:
        run_campaign(SMOKE, out, workers=1, resume=True)
    text = str(err.value)
    assert f"holds rows computed by other code (2 by {other}; 1 by unknown" in text
    assert f"this is {code_id()}" in text and "--allow-code-change" in text
    assert _listing(out) == before
    # Allowed, it goes on to the cluster.
    with pytest.raises(_NoCluster):
        run_campaign(SMOKE, out, workers=1, resume=True, allow_code_change=True)
    # Rows of this code alone resume.
    same = tmp_path / "same"
    _stored_campaign(same, [code_id(), code_id()])
    with pytest.raises(_NoCluster):
        run_campaign(SMOKE, same, workers=1, resume=True)


def test_a_finished_campaign_of_other_code_is_summarised_again(tmp_path, no_cluster):
    """With no run left to do, a resume mixes nothing: it writes the summary
    of the stored rows (no cluster needed), naming their code."""
    out = tmp_path / "done"
    other = "vic_drake 0.1.0 source 0123456789ab, drake 1.40.0, python 3.10.0"
    _stored_campaign(out, [other] * 16)
    summary = run_campaign(SMOKE, out, workers=1, resume=True)
    assert summary["code_ids"] == {other: 16} and summary["session_runs"] == 0
    assert f"Computed by {other}." in (out / "summary.html").read_text()


def test_a_resume_with_another_base_scenario_or_spec_shows_what_differs(
    tmp_path, no_cluster
):
    """The base scenario's contents count, not only its path: a base file
    edited between the start and the resume is refused, with the lines."""
    from vic_drake.provenance import code_id

    out = tmp_path / "c"
    before = _stored_campaign(out, [code_id()] * 2)
    base = out / engine.CAMPAIGN_BASE_FILE
    base.write_text(
        base.read_text().replace("approach_z_m: 0.11", "approach_z_m: 0.12")
    )
    with pytest.raises(VicDrakeError) as err:
        run_campaign(SMOKE, out, workers=1, resume=True)
    text = str(err.value)
    assert "holds another base scenario (base_scenario.yaml); --resume" in text
    # The lines that differ, with their line number.
    assert "Stored (-) and now (+): -8 +8:; -  approach_z_m: 0.12; " in text
    assert "+  approach_z_m: 0.11" in text
    assert _listing(out) == before
    spec = out / "spec.yaml"
    base.unlink()  # A folder from before bases were kept: not checked.
    spec.write_text(spec.read_text().replace("runs: 16", "runs: 8"))
    with pytest.raises(
        VicDrakeError, match=r"another campaign spec .*-runs: 8; \+runs: 16"
    ):
        run_campaign(SMOKE, out, workers=1, resume=True)


def test_a_resume_runs_the_failed_runs_again(tmp_path, no_cluster):
    """A run that failed with an error (a worker lost, a broken node) has no
    result: a resume runs it again; an ok run it keeps."""
    from vic_drake.provenance import code_id

    out = tmp_path / "c"
    _stored_campaign(out, [code_id()] * 3)
    for name in ("run_00001", "run_00002"):
        row = json.loads((out / "rows" / f"{name}.json").read_text())
        row.update(status="error", error="its process exited with status -9")
        (out / "rows" / f"{name}.json").write_text(json.dumps(row))
    lines = []
    with pytest.raises(_NoCluster):
        run_campaign(SMOKE, out, workers=1, resume=True, progress=lines.append)
    assert lines == [
        f"2 runs of {str(out)!r} failed with an error before: running them again"
    ]
    assert engine._check_out(out, _texts(), _plans(), True, lambda _: None) == {
        "run_00000"
    }
    # A resume refused (the kept row is another code's) promises no rerun.
    row = json.loads((out / "rows" / "run_00000.json").read_text())
    row["code_id"] = "vic_drake 0.0.9 source 000000000000, drake 1.40.0, python 3.10.0"
    (out / "rows" / "run_00000.json").write_text(json.dumps(row))
    lines.clear()
    with pytest.raises(VicDrakeError, match="holds rows computed by other code"):
        run_campaign(SMOKE, out, workers=1, resume=True, progress=lines.append)
    assert lines == []


def _plans():
    from vic_drake.experiments.campaign.plan import plan_campaign
    from vic_drake.experiments.campaign.spec import load_campaign_spec
    from vic_drake.scenario import load_scenario

    spec, base = load_campaign_spec(SMOKE)
    return plan_campaign(spec, load_scenario(base))


def test_the_summary_counts_the_rows_per_code():
    from vic_drake.experiments.campaign.engine import UNKNOWN_CODE, summary_dict

    spec = CampaignSpec(runs=3)
    rows = _rows().assign(code_id=["a", "b", None])
    summary = summary_dict(spec, rows)
    assert summary["code_ids"] == {"a": 1, "b": 1, UNKNOWN_CODE: 1}
    page = summary_html(Path("."), spec, rows, summary)
    assert "The rows come from more than one code" in page and "1 by b" in page
    assert "more than one code" in _human(
        {**_result(3), "code_ids": summary["code_ids"]}
    )
    one = summary_dict(spec, rows.assign(code_id="a"))
    assert one["code_ids"] == {"a": 3}
    assert "Computed by a." in summary_html(Path("."), spec, rows, one)
    assert "code" not in _human({**_result(3), "code_ids": one["code_ids"]})


def test_a_campaign_that_cannot_start_leaves_no_folder(tmp_path, monkeypatch):
    def unreachable(workers, scheduler):
        raise VicDrakeError(f"cannot reach the Dask scheduler {scheduler!r}")

    monkeypatch.setattr(engine, "dask_session", unreachable)
    out = tmp_path / "c2"
    for _ in range(2):  # The retry is not refused as "already holds a campaign".
        with pytest.raises(VicDrakeError, match="cannot reach the Dask scheduler"):
            run_campaign(SMOKE, out, scheduler="localhost:1")
        assert not out.exists()


def test_tankless_controllers_have_nan_tank_metrics():
    t = np.arange(0, 3, 0.002)
    df = pd.DataFrame(
        {
            "t_s": t,
            "z_d_m": 0.085,
            "force_sensor_z_N": -7.0,
            "force_tissue_z_N": -7.0,
            "tank_energy_J": 0.5,  # What CS and CF log: the initial energy.
            "qp_ok": 1.0,
            "qp_fault": 0.0,
        }
    )
    assert math.isnan(run_metrics(df, force_limit_N=15.0, has_tank=False)["tank_min_J"])
    assert run_metrics(df, force_limit_N=15.0)["tank_min_J"] == 0.5


def test_contact_losses_count_up_to_the_watchdogs_stop():
    t = np.arange(0, 6, 0.002)
    lost = (t > 3.0) & (t < 3.5) | (t > 4.5)  # A loss, then the stop's retract.
    df = pd.DataFrame(
        {
            "t_s": t,
            "z_d_m": np.where(t < 5.5, 0.085, 0.12),
            "force_sensor_z_N": np.where(lost, 0.0, -7.0),
            "force_tissue_z_N": np.where(lost, 0.0, -7.0),
            "tank_energy_J": 0.5,
            "qp_ok": 1.0,
            "qp_fault": 0.0,
        }
    )
    everything = run_metrics(df, force_limit_N=15.0)["contact_loss_s"]
    stopped = run_metrics(df, force_limit_N=15.0, stop_s=4.5)["contact_loss_s"]
    assert stopped == pytest.approx(0.5, abs=0.005)
    assert everything == pytest.approx(0.5, abs=0.005)  # No contact after 4.5 s.
    # A stop inside a loss ends it there.
    assert run_metrics(df, force_limit_N=15.0, stop_s=3.2)[
        "contact_loss_s"
    ] == pytest.approx(0.2, abs=0.005)


def test_the_controllers_figures_after_the_watchdogs_stop_do_not_count():
    # After the stop the QP and the tank run on the stale sensor (e.g. a
    # stuck pressing reading while the probe lifts: the QP fails), but the
    # arm follows the retract, not them.
    t = np.arange(0, 4, 0.002)
    after = t >= 2.0
    df = pd.DataFrame(
        {
            "t_s": t,
            "z_d_m": 0.085,
            "force_sensor_z_N": -7.0,
            "force_tissue_z_N": np.where(after, 0.0, -7.0),
            "tank_energy_J": np.where(after, 0.3, 0.5),
            "qp_ok": np.where(after, 0.0, 1.0),
            "qp_fault": 0.0,
        }
    )
    whole = run_metrics(df, force_limit_N=15.0)
    assert whole["qp_failures"] == 1000 and whole["tank_min_J"] == 0.3
    stopped = run_metrics(df, force_limit_N=15.0, stop_s=2.0)
    assert stopped["qp_failures"] == 0 and stopped["tank_min_J"] == 0.5


def test_ticks_skipped_on_a_non_finite_input_are_not_failed_solves():
    t = np.arange(0, 4, 0.002)
    nan_reading = (t >= 1.0) & (t < 1.1)  # The QP is skipped: K = K_min.
    failed = (t >= 2.0) & (t < 2.01)  # The solver fails.
    df = pd.DataFrame(
        {
            "t_s": t,
            "z_d_m": 0.085,
            "force_sensor_z_N": -7.0,
            "force_tissue_z_N": -7.0,
            "tank_energy_J": 0.5,
            "qp_ok": np.where(nan_reading | failed, 0.0, 1.0),
            "qp_fault": np.where(nan_reading, 1.0, 0.0),
        }
    )
    metrics = run_metrics(df, force_limit_N=15.0)
    assert metrics["qp_failures"] == 5 and metrics["input_faults"] == 50
    stopped = run_metrics(df, force_limit_N=15.0, stop_s=1.05)
    assert stopped["qp_failures"] == 0 and stopped["input_faults"] == 25
    with pytest.raises(VicDrakeError, match="qp_fault"):
        run_metrics(df.drop(columns="qp_fault"), force_limit_N=15.0)


def _rows() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "run_id": ["run_00000", "run_00001", "run_00002"],
            "index": [0, 1, 2],
            "status": ["ok"] * 3,
            "error": [""] * 3,
            "factor.controller": ["cs", "cf", "vs-vf"],
            "peak_force_N": [7.4, 8.3, 7.1],
            "contact_loss_s": [0.0, 0.0, 0.0],
            "tank_min_J": [math.nan, math.nan, 0.444],
            "watchdog_trip_s": [math.nan, 2.1, math.nan],
        }
    )


def _result(session_runs: int, finished: int = 16) -> dict:
    return {
        "runs": 16,
        "finished": finished,
        "failed": 0,
        "nan_runs": 0,
        "session_runs": session_runs,
        "wall_s": 15.0,
        "runs_per_hour": session_runs / 15.0 * 3600,
        "workers": 2,
        "force_limit_N": 15.0,
        "per_controller": per_controller(_rows(), 15.0),
    }


def test_the_console_table_shows_a_dash_for_no_tank():
    text = _human(_result(16))
    cs, cf, vs = (
        next(line.split() for line in text.splitlines() if line.startswith(name))
        for name in ("cs ", "cf ", "vs-vf ")
    )
    assert cs[-2] == "-" and vs[-2] == "0.444"
    # The last column: runs the sensor's watchdog stopped.
    assert text.splitlines()[1].endswith("wd stops")
    assert (cs[-1], cf[-1], vs[-1]) == ("0", "1", "0")
    assert "nan" not in "\n".join(text.splitlines()[1:])  # The table, not "0 NaN".


def test_the_summary_page_shows_a_dash_for_no_tank(tmp_path):
    rows = _rows()
    summary = {**_result(3, finished=3), "runs": 3}
    page = summary_html(tmp_path, CampaignSpec(runs=3), rows, summary)
    assert "<td>—</td>" in page and "<td>0.444</td>" in page
    assert "<td>NaN</td>" not in page and "nan</td>" not in page


def test_the_campaign_command_says_when_rows_come_from_two_codes(monkeypatch, capsys):
    """After a resume with --allow-code-change the console says so, as the
    summary's files do (the command passes the counts on to its words)."""
    from vic_drake.cli import main
    from vic_drake.experiments import campaign

    codes = {"code a": 10, "code b": 6}
    monkeypatch.setattr(
        campaign, "run_campaign", lambda *a, **k: {**_result(16), "code_ids": codes}
    )
    assert main(["campaign", str(SMOKE), "--out", "unused"]) == 0
    out = capsys.readouterr().out
    assert (
        "rows from more than one code (--allow-code-change): 10 by code a; 6 by code b"
        in out
    )


def test_the_campaign_command_prints_the_watchdogs_stops(monkeypatch, capsys):
    """The command's words show the stops that its --json (a contract)
    leaves to summary.json."""
    from vic_drake.cli import main
    from vic_drake.experiments import campaign

    monkeypatch.setattr(campaign, "run_campaign", lambda *a, **k: _result(16))
    assert main(["campaign", str(SMOKE), "--out", "unused"]) == 0
    lines = capsys.readouterr().out.splitlines()
    cf = next(line.split() for line in lines if line.startswith("cf "))
    assert cf[-1] == "1"


def test_after_a_resume_the_rate_is_this_sessions_and_says_so():
    # 8 runs in 15 s after 8 done before: 1920 runs/h, and the line says
    # that these are 8 runs, not the 16 finished.
    line = _human(_result(8)).splitlines()[0]
    assert line == (
        "16/16 runs done: 16 ok, 0 failed (0 of them NaN); this session 8 runs in "
        "15 s on "
        "2 workers, 1920 runs/h (8 finished before)"
    )
    assert (
        _human(_result(16))
        .splitlines()[0]
        .endswith("16 runs in 15 s on 2 workers, 3840 runs/h")
    )
    assert _human(_result(0)).splitlines()[0].endswith("nothing left to run")


def test_a_paired_campaign_summarises_its_arms_run_for_run(tmp_path):
    from vic_drake.experiments.campaign import load_campaign_spec

    campaigns = Path(__file__).resolve().parents[3] / "campaigns"
    spec, _ = load_campaign_spec(campaigns / "robustness_online.yaml")
    assert spec.paired and spec.grid_size == 2
    rows = pd.DataFrame(
        {
            "run_id": [f"run_{i:05d}" for i in range(4)],
            "index": range(4),
            "status": ["ok"] * 4,
            "error": [""] * 4,
            "factor.controller": ["vs-vf", "vs-vf online"] * 2,
            "peak_force_N": [9.0, 9.5, 10.0, 9.0],
            "contact_loss_s": [0.0, 0.5, 0.0, 0.2],
            "tank_min_J": [0.4] * 4,
        }
    )
    summary = engine.summary_dict(spec, rows)
    (pair,) = summary["paired"]
    assert (pair["first"], pair["second"], pair["pairs"]) == (
        "vs-vf",
        "vs-vf online",
        2,
    )
    page = summary_html(tmp_path, spec, rows, summary)
    assert "Paired arms" in page and "<td>0 / 2 / 0 (p = " in page
    unpaired = CampaignSpec(runs=4)
    assert "paired" not in engine.summary_dict(unpaired, rows)


def _small_campaign():
    """An 8-run campaign's rows (2 per controller) and its summary; vs-cf's
    first run was stopped before it touched the patient."""
    spec = CampaignSpec(
        name="mini",
        description="a dead sensor, the four controllers, 200 runs of 4 s",
        runs=8,
        duration_s=4.0,
    )
    rows = pd.DataFrame(
        {
            "run_id": [f"run_{i:05d}" for i in range(8)],
            "index": range(8),
            "status": ["ok"] * 8,
            "error": [""] * 8,
            "factor.controller": ["cs", "cf", "vs-cf", "vs-vf"] * 2,
            "factor.amp": [
                0.0102949,
                0.0116131,
                0.0035657,
                0.0076874,
                0.0041175,
                0.0120750,
                0.0118827,
                0.0106774,
            ],
            "factor.mode": ["hold", "nan"] * 4,
            "peak_force_N": [6.84, 10.34, 0.0, 6.61, 5.80, 7.37, 7.80, 4.26],
            "contact_loss_s": [0.0] * 8,
            "tank_min_J": [math.nan, math.nan, 0.465, 0.484] * 2,
            "watchdog_trip_s": [
                math.nan,
                math.nan,
                0.964,
                1.32,
                3.29,
                1.83,
                3.74,
                1.01,
            ],
            "watchdog_cause": ["", "", "all", "all", "all", "all", "all", "all"],
            "qp_failures": [0] * 8,
            "input_faults": [0, 114, 98, 0, 0, 0, 98, 73],
        }
    )
    return spec, rows, engine.summary_dict(spec, rows)


def _tables(page: str) -> list[str]:
    return page.split("<table>")[1:]


def test_a_small_campaigns_factor_effects_say_too_few_runs(tmp_path):
    spec, rows, summary = _small_campaign()
    page = summary_html(tmp_path, spec, rows, summary)
    # Per controller, the runs that touched the patient (vs-cf's other did not).
    assert (
        "too few runs per controller (cf: 2, cs: 2, vs-cf: 1, vs-vf: 2)" in page.lower()
    )
    assert "1 run without contact" in page
    # Every table has a body; no factor value is shown as a label.
    assert all("<td>" in t.split("</table>")[0] for t in _tables(page))
    assert "0.0102949" not in page and "hold:" not in page


def test_the_summary_page_explains_its_columns_with_the_force_limit(tmp_path):
    spec, rows, summary = _small_campaign()
    page = summary_html(tmp_path, spec, rows, summary)
    legend = page.split("<h2>Per controller</h2>")[1].split("<h2>")[0]
    assert "15 N" in legend and "force limit" in legend
    for words in ("peak F", "tank min", "—", "no energy tank", "tissue"):
        assert words in legend, words
    # The runs as run, beside the spec's own words (which say 200).
    assert "8 runs of 4 s" in page


def test_runs_that_never_touched_are_counted_in_the_table_and_the_console(tmp_path):
    spec, rows, summary = _small_campaign()
    assert summary["per_controller"]["vs-cf"]["no_contact_runs"] == 1
    page = summary_html(tmp_path, spec, rows, summary)
    per_controller_table = _tables(page)[0]
    assert "<th>never touched the patient</th>" in per_controller_table
    assert "<tr><td>vs-cf</td><td>2</td><td>1</td><td>7.8</td>" in per_controller_table
    result = {
        **summary,
        "session_runs": 8,
        "wall_s": 40.0,
        "runs_per_hour": 720.0,
        "workers": 1,
    }
    text = _human(result)
    header = text.splitlines()[1].split()
    assert "P(>15" in header and "contact" in header
    vs = next(line.split() for line in text.splitlines() if line.startswith("vs-cf "))
    assert vs[1:4] == ["2", "1", "7.80"]
    assert "15 N" in text.split("wd stops", 1)[1]  # The legend under the table.


def test_the_page_lists_what_varies_and_replays_from_any_folder(tmp_path, monkeypatch):
    """The factors as the spec draws them; the worst runs' replay commands
    with the folder made absolute (a relative --out worked only from where
    the campaign ran)."""
    from vic_drake.experiments.campaign.spec import Factor

    spec = CampaignSpec(
        runs=3,
        factors=[
            Factor(field="controller", dist="grid", labels=["cs", "cf", "vs-vf"]),
            Factor(field="variations.sensor_faults.noise_std_N", low=0.2, high=1.0),
            Factor(
                field="variations.sensor_faults.bias_N[2]",
                dist="normal",
                std=1.0,
                low=-3.0,
                high=3.0,
            ),
        ],
    )
    rows = _rows()
    summary = {**_result(3, finished=3), "runs": 3}
    monkeypatch.chdir(tmp_path)
    page = summary_html(Path("rel") / "camp", spec, rows, summary)
    assert "<h2>What varies</h2>" in page
    assert "grid: cs, cf, vs-vf (each round of runs has every one)" in page
    assert "uniform from 0.2 to 1" in page
    assert "normal, mean 0, std 1, clipped to [-3, 3]" in page
    absolute = tmp_path / "rel" / "camp" / "scenarios"
    assert f"vic-drake scan {absolute}/run_" in page
    assert "vic-drake scan rel/" not in page
