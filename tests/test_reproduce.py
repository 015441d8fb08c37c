"""The reproduce pipeline: stages, outputs, errors (fast stages only here)."""

import json

import pytest

from vic_drake.cli import main
from vic_drake.errors import VicDrakeError
from vic_drake.reproduce import (
    REAL_SCAN_LOGS,
    ReproduceOptions,
    real_scan_frame,
    reproduce,
)


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


@pytest.mark.realdata
def test_real_logs_claims_and_report(tmp_path, data_dir):
    result = reproduce(ReproduceOptions(
        out_dir=tmp_path, data_dir=data_dir,
        stages=("real_scans", "claims", "report")))
    claims = json.loads((tmp_path / "claims.json").read_text())
    assert list(claims) == [f"C{i}" for i in range(1, 8)]
    for c in claims.values():
        assert isinstance(c["pass"], bool)
        assert set(c) >= {"statement", "paper", "sim", "real", "pass"}
    # Without the simulated stages no claim passes (sim not evaluated).
    assert not any(c["pass"] for c in claims.values())
    # The real rig's logs support C3-C6 (values computed, not stored).
    for cid in ("C3", "C4", "C5", "C6"):
        assert claims[cid]["pass_real"] is True, claims[cid]
    assert claims["C4"]["real"]["rmse_ratio"] < 1.0
    assert claims["C7"]["real"] is None and "VS-VF" in claims["C7"]["detail"]
    assert result.report_path.is_file()
    assert "Claims (0 of 7 pass)" in result.report_path.read_text()


@pytest.mark.realdata
def test_real_scan_frame_layouts(data_dir):
    from vic_drake.realdata import read_bag

    cf = real_scan_frame(read_bag(data_dir / "experiments" / REAL_SCAN_LOGS[("nominal", "cf")]),
                         controller="cf")
    assert (cf["force_ref_z_N"] == -7.0).all()
    assert cf["force_sensor_z_N"].median() < 0  # pressing: negative in sensor sign
    vsvf = real_scan_frame(read_bag(data_dir / "experiments"
                                    / REAL_SCAN_LOGS[("nominal", "vs-vf")]))
    # Tank power = change per tick / tick period; the valve holds it near -0.1 W.
    assert vsvf["tank_power_W"].min() == pytest.approx(-0.1, abs=0.01)


def test_scan_scenarios_cover_the_paper_runs():
    from vic_drake.reproduce import CONTROLLERS, scan_limits, scan_scenario

    for quick in (True, False):
        for c in CONTROLLERS:
            s = scan_scenario(c, disturbed=False, phantom_kind="synthetic", quick=quick)
            assert s.controller.reference.controller == c
            assert s.disturbance.is_nominal
        d = scan_scenario("vs-vf", disturbed=True, phantom_kind="synthetic", quick=quick)
        lifts = d.disturbance.lifts
        assert len(lifts) == (2 if quick else 4)
        # Every event ends (phantom back at rest) before the target lifts off.
        traj = d.trajectory
        scan_end = traj.end_time_s - traj.liftoff_s
        for lift in lifts:
            assert lift.start_s + lift.rise_s + lift.hold_s + lift.fall_s < scan_end
        # Dropped below rest: contact loss must be possible.
        assert min(lift.height_m for lift in lifts) < 0
    lim = scan_limits(scan_scenario("vs-vf", disturbed=False, phantom_kind="synthetic",
                                    quick=True))
    assert lim.k_min_z_N_per_m == 100.0 and lim.tank_min_J == 0.4
    assert lim.power_max_W == pytest.approx(0.1) and lim.eps_d_m == 0.008


@pytest.mark.slow
def test_reproduce_quick_end_to_end(tmp_path):
    """The whole quick pipeline: every stage runs, every output exists."""
    assert main(["reproduce", "--quick", "--out", str(tmp_path), "--quiet"]) == 0
    run = json.loads((tmp_path / "run.json").read_text())
    failed = [s for s in run["stages"] if s["status"] == "failed"]
    assert not failed, failed
    skipped = [s["name"] for s in run["stages"] if s["status"] == "skipped"]
    assert skipped == ["compare_real"]  # full mode only
    claims = json.loads((tmp_path / "claims.json").read_text())
    assert all(c["sim"] is not None for c in claims.values())
    assert (tmp_path / "report.html").stat().st_size > 100_000
    assert (tmp_path / "replay.html").is_file()
    logs = sorted(p.name for p in (tmp_path / "logs").iterdir())
    parquet = [n for n in logs if n.endswith(".parquet")]
    # 7 scans, the simulated palpation (quick: one) and the map campaign.
    assert len(parquet) == 9, parquet
    for n in parquet:  # every log has its configuration beside it
        assert n.replace(".parquet", ".yaml") in logs


def test_offline_sim_stage_evaluates_c1_and_c2(tmp_path, monkeypatch):
    """Palpations simulated on the synthetic chest (no data needed)."""
    monkeypatch.setenv("VIC_DRAKE_DATA", str(tmp_path / "no_data"))
    out = tmp_path / "out"
    result = reproduce(ReproduceOptions(out_dir=out, quick=True, phantom="synthetic",
                                        stages=("offline_sim", "claims", "report")))
    c1, c2 = result.claims["C1"], result.claims["C2"]
    assert c1["pass_sim"] is True and c1["sim"]["best_beta"] == pytest.approx(1.35)
    assert c1["real"] is None and c1["pass_real"] is None
    assert c2["sim"] is not None and c2["pass_sim"] in (True, False)
    assert (out / "logs" / "palpation_sim_2.5hz.parquet").is_file()
    assert (out / "logs" / "palpation_sim_2.5hz.yaml").is_file()
    assert (out / "figures" / "table1_sim.png").is_file()


def test_replay_scan_writes_an_animation():
    import numpy as np
    import pandas as pd

    from vic_drake.reproduce import replay_scan, scan_scenario
    from vic_drake.station import initial_q_for_tip
    from vic_drake.tissue import load_phantom

    scenario = scan_scenario("vs-vf", disturbed=False, phantom_kind="synthetic", quick=True)
    q0 = initial_q_for_tip(np.array([0.036, -0.36, 0.11]), scenario.station)
    t = np.linspace(0, 0.4, 11)
    df = pd.DataFrame({"t_s": t, "phantom_lift_m": 0.01 * t,
                       **{f"q_cmd_{i}_rad": np.full(t.size, q0[i]) for i in range(6)}})
    html = replay_scan(df, scenario, phantom=load_phantom("synthetic"), fps=20.0)
    import base64
    import re

    # The recording is one base64 msgpack command "set_animation" among the scene's.
    blobs = re.findall(r'fetch\("data:application/octet-binary;base64,([^"]+)"\)', html)
    assert sum(b"set_animation" in base64.b64decode(b) for b in blobs) == 1
    with pytest.raises(VicDrakeError, match="lacks columns"):
        replay_scan(df.drop(columns=["q_cmd_0_rad"]), scenario,
                    phantom=load_phantom("synthetic"))
