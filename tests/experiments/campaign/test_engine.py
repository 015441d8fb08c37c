"""Campaigns end to end on Dask: smoke, an external cluster, interrupt + resume."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

from vic_drake.cli import main
from vic_drake.commands.campaign import CONTROLLER_KEYS, JSON_KEYS
from vic_drake.experiments.campaign import load_campaign_spec, plan_campaign, read_rows
from vic_drake.scenario import load_scenario

CAMPAIGNS = Path(__file__).resolve().parents[3] / "campaigns"
SMOKE = CAMPAIGNS / "smoke.yaml"
#: Row fields that differ between two runs of the same campaign.
TIMING = ["wall_s"]


def _run_cli(args, capsys) -> tuple[dict, str]:
    """(the --json result, stderr) of one campaign command."""
    code = main(["campaign", *map(str, args), "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    return json.loads(captured.out), captured.err


def _planned_ids(spec_path) -> list[str]:
    spec, base = load_campaign_spec(spec_path)
    return [p.run_id for p in plan_campaign(spec, load_scenario(base))]


def _comparable(rows: pd.DataFrame) -> pd.DataFrame:
    return rows.drop(columns=TIMING).sort_values("run_id").reset_index(drop=True)


@pytest.fixture(scope="module")
def smoke_local(tmp_path_factory):
    out = tmp_path_factory.mktemp("smoke") / "local"
    code = main(["campaign", str(SMOKE), "--out", str(out), "--workers", "2", "--json"])
    assert code == 0
    return out


def _strict_json(path: Path):
    """A file's JSON, refusing NaN and infinities (as a strict parser does)."""

    def refuse(constant):
        raise ValueError(f"{path.name} holds {constant}, which is not JSON")

    return json.loads(path.read_text(), parse_constant=refuse)


def test_smoke_campaign_passes_with_no_failed_or_nan_run(smoke_local):
    summary = _strict_json(smoke_local / "summary.json")
    for row in (smoke_local / "rows").glob("run_*.json"):
        _strict_json(row)
    assert summary["finished"] == summary["runs"] == 16
    assert summary["failed"] == 0 and summary["nan_runs"] == 0
    assert set(summary["per_controller"]) == {"cs", "cf", "vs-cf", "vs-vf"}
    for entry in summary["per_controller"].values():
        assert entry["runs"] == 4
        assert set(CONTROLLER_KEYS) <= set(entry)
    rows = read_rows(smoke_local)
    assert sorted(rows["run_id"]) == _planned_ids(SMOKE)
    assert (rows["status"] == "ok").all()
    assert (rows["watchdog_cause"] == "").all()  # No fault stopped a run.
    assert (rows["qp_failures"] == 0).all() and (rows["input_faults"] == 0).all()
    assert rows["peak_force_N"].between(1.0, 40.0).all()  # Every probe pressed.
    vs = rows[rows["factor.controller"].str.startswith("vs")]
    assert (vs["tank_min_J"] >= vs["tank_floor_J"] - 1e-9).all()
    # CS and CF have no tank: no floor, no minimum (their log holds 0.5 J).
    tankless = rows[rows["factor.controller"].isin(["cs", "cf"])]
    assert tankless[["tank_min_J", "tank_floor_J"]].isna().all().all()
    tank = {k: v["tank_min_J"] for k, v in summary["per_controller"].items()}
    assert tank["cs"] is None and tank["cf"] is None  # null: no tank.
    assert 0.4 <= tank["vs-cf"] < 0.5 and 0.4 <= tank["vs-vf"] < 0.5
    table = pd.read_parquet(smoke_local / "results.parquet")
    assert len(table) == 16
    # Each run's scenario replays: it is the run's own, loadable by scan.
    spec, base = load_campaign_spec(SMOKE)
    plans = plan_campaign(spec, load_scenario(base))
    assert (
        load_scenario(smoke_local / "scenarios" / "run_00007.yaml")
        == plans[7].scenario()
    )
    page = (smoke_local / "summary.html").read_text()
    assert "ten worst runs" in page and "vic-drake scan" in page


def test_json_output_has_exactly_the_contract_keys(smoke_local, capsys):
    # A resume of a finished campaign runs nothing and reports it.
    result, _ = _run_cli([SMOKE, "--out", smoke_local, "--resume"], capsys)
    assert list(result) == list(JSON_KEYS)
    assert result["finished"] == 16 and result["runs_per_hour"] == 0.0
    assert result["session_runs"] == 0
    assert result["per_controller"]["cs"]["tank_min_J"] is None  # NaN: no tank.
    for entry in result["per_controller"].values():
        assert list(entry) == list(CONTROLLER_KEYS)
        assert len(entry["exceed_prob_ci95"]) == 2


def test_bad_invocations_are_clear_errors(tmp_path, smoke_local, capsys):
    assert main(["campaign", str(tmp_path / "none.yaml"), "--out", str(tmp_path)]) == 2
    assert "does not exist" in capsys.readouterr().err
    # An existing campaign folder needs --resume.
    assert main(["campaign", str(SMOKE), "--out", str(smoke_local)]) == 2
    assert "--resume" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["campaign", str(SMOKE), "--out", str(tmp_path), "--workers", "0"])


def _start(cmd, log: Path):
    return subprocess.Popen(
        cmd, stdout=log.open("w"), stderr=subprocess.STDOUT, start_new_session=True
    )


def _kill_after_rows(out: Path, proc, rows: int = 3) -> None:
    deadline = time.time() + 900
    while time.time() < deadline:
        if len(list((out / "rows").glob("run_*.json"))) >= rows:
            os.killpg(proc.pid, signal.SIGKILL)
            return
        time.sleep(0.2)


@pytest.mark.slow
def test_external_dask_cluster_gives_the_same_rows(smoke_local, tmp_path, capsys):
    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
    worker = [sys.executable, "-m", "distributed.cli.dask_worker"]
    sched_file = tmp_path / "scheduler.json"
    procs = [
        _start(
            [
                *dask,
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                str(sched_file),
            ],
            tmp_path / "scheduler.log",
        )
    ]
    try:
        for _ in range(120):
            if sched_file.exists():
                break
            time.sleep(0.5)
        address = json.loads(sched_file.read_text())["address"]
        for i in range(2):
            procs.append(
                _start(
                    [
                        *worker,
                        address,
                        "--nthreads",
                        "1",
                        "--no-dashboard",
                        "--name",
                        f"w{i}",
                    ],
                    tmp_path / f"worker{i}.log",
                )
            )
        time.sleep(5)
        out = tmp_path / "external"
        # One worker dies (SIGKILL) once 3 runs are done: it loses its
        # current run, which the other worker runs again.
        killer = threading.Thread(target=_kill_after_rows, args=(out, procs[2]))
        killer.start()
        result, _ = _run_cli([SMOKE, "--out", out, "--scheduler", address], capsys)
        killer.join()
        assert procs[2].poll() is not None  # The worker did die mid-campaign.
        assert result["workers"] == 2 and result["failed"] == 0
        pd.testing.assert_frame_equal(
            _comparable(read_rows(out)), _comparable(read_rows(smoke_local))
        )
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
                p.wait(timeout=30)


@pytest.mark.slow
def test_interrupted_campaign_resumes_to_exactly_the_planned_runs(tmp_path, capsys):
    spec = tmp_path / "spec.yaml"
    spec.write_text(
        f"name: resume\nbase_scenario: {CAMPAIGNS / 'base' / 'short_scan_synthetic.yaml'}\n"
        "runs: 8\nseed: 5\nduration_s: 0.6\n"
        "factors:\n  - {field: controller, dist: grid, labels: [cs, vs-vf]}\n"
    )
    out = tmp_path / "out"
    cli = [
        sys.executable,
        "-m",
        "vic_drake.cli",
        "campaign",
        str(spec),
        "--out",
        str(out),
    ]
    proc = subprocess.Popen([*cli, "--workers", "1"], stderr=subprocess.PIPE, text=True)
    rows_dir = out / "rows"
    deadline = time.time() + 600
    while time.time() < deadline:
        if rows_dir.exists() and len(list(rows_dir.glob("run_*.json"))) >= 3:
            break
        time.sleep(0.2)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    before = {p.name: p.read_text() for p in rows_dir.glob("run_*.json")}
    assert 3 <= len(before) < 8
    result, err = _run_cli([spec, "--out", out, "--workers", "1", "--resume"], capsys)
    assert result["finished"] == 8 and result["failed"] == 0
    rows = read_rows(out)
    assert sorted(rows["run_id"]) == _planned_ids(spec)  # Each planned run once.
    for name, text in before.items():  # Finished runs were not run again.
        assert (rows_dir / name).read_text() == text
    assert f"] {8 - len(before)} runs on 1 Dask workers" in err
    assert result["session_runs"] == 8 - len(before)  # The rate's runs.


def _campaign_as_a_terminal_starts_it(tmp_path, runs: int):
    """A local campaign of short CS and VS-VF scans on 2 workers, in a
    process group of its own as a terminal starts it: (proc, spec, out)."""
    spec = tmp_path / "spec.yaml"
    spec.write_text(
        f"name: stop\nbase_scenario: {CAMPAIGNS / 'base' / 'short_scan_synthetic.yaml'}\n"
        f"runs: {runs}\nseed: 5\nduration_s: 0.6\n"
        "factors:\n  - {field: controller, dist: grid, labels: [cs, vs-vf]}\n"
    )
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "vic_drake.cli", "campaign", str(spec)]
    proc = subprocess.Popen(
        [*cmd, "--out", str(out), "--workers", "2"],
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    return proc, spec, out


def _wait_until_the_group_is_gone(pgid: int) -> None:
    for _ in range(100):  # No worker nor run process is left behind.
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return
        time.sleep(0.1)
    pytest.fail("processes of the campaign's group are still running")


@pytest.mark.slow
def test_ctrl_c_stops_quietly_and_says_how_to_finish(tmp_path):
    """Ctrl-C as a terminal sends it: to the whole process group (the
    campaign, its Dask workers, their runs' processes), and twice, as
    ``timeout -s INT`` does."""
    proc, spec, out = _campaign_as_a_terminal_starts_it(tmp_path, 8)
    rows_dir = out / "rows"
    deadline = time.time() + 600
    while time.time() < deadline and proc.poll() is None:
        if rows_dir.exists() and len(list(rows_dir.glob("run_*.json"))) >= 1:
            break
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGINT)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    kept = len(list(rows_dir.glob("run_*.json")))
    assert "Traceback" not in err and "WARNING" not in err, err
    assert f"interrupted: {kept} of 8 runs done, kept in {str(out)!r}" in err
    assert f"finish the campaign with: vic-drake campaign {spec} --out {out}" in err
    assert err.rstrip().endswith("--resume\nvic-drake: interrupted"), err
    _wait_until_the_group_is_gone(proc.pid)


def _group_size(pgid: int) -> int:
    """Processes in the process group (Linux /proc)."""
    n = 0
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[2]) == pgid:
                n += 1
    return n


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_ctrl_c_while_the_cluster_starts_leaves_nothing(tmp_path):
    """Ctrl-C to the whole group while the worker processes start: the
    campaign says it was interrupted, and nothing else (no worker's
    traceback, no Dask log), leaves no process and no folder."""
    proc, _, out = _campaign_as_a_terminal_starts_it(tmp_path, 4)
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        if _group_size(proc.pid) > 1:  # The first worker processes are up.
            break
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGINT)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert err == "vic-drake: interrupted\n", err
    assert not out.exists()
    _wait_until_the_group_is_gone(proc.pid)


def test_a_run_row_says_what_stopped_it():
    from vic_drake.experiments.campaign.run import execute_run

    spec, base = load_campaign_spec(CAMPAIGNS / "robustness_dead.yaml")
    dies_at = "variations.sensor_faults.dead_start_s"
    mode = "variations.sensor_faults.dropout_mode"
    # The first run whose sensor dies well before its end, into NaN.
    plan = next(
        p
        for p in plan_campaign(spec, load_scenario(base))
        if p.factors[dies_at] < 3.5 and p.factors[mode] == "nan"
    )
    row = execute_run(plan)
    dies = plan.factors[dies_at]
    assert row["status"] == "ok" and row["watchdog_cause"] == "all"
    assert row["watchdog_trip_s"] <= dies + 0.1 + 1e-9
    # The NaN ticks before the stop skip the QP: input faults, not failed
    # solves (the run's short NaN dropouts before its death add to them).
    period = load_scenario(base).logging.period_s  # One logged sample a tick.
    assert row["qp_failures"] == 0
    assert row["input_faults"] >= (row["watchdog_trip_s"] - dies) / period - 2
