"""The ``online`` stage: the estimators replayed over real logs and a simulated scan."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.estimation.online import OnlineEstimatorParams
from vic_drake.reproduce import ReproduceOptions, reproduce
from vic_drake.reproduce.stages.online import replay_simulated_scan
from vic_drake.tissue import load_phantom
from vic_drake.tissue.models import hunt_crossley_force


def _hc_scan(phantom, depth_m=0.006, seconds=6.0, rate_hz=500.0):
    """A probe sliding along x at a constant depth on HC tissue, 0.05 N noise."""
    t = np.arange(0.0, seconds, 1.0 / rate_hz)
    x = -0.02 - 0.01 * t
    y = np.full_like(t, -0.36)
    tissue = phantom.sample(x, y)
    z = np.asarray(tissue.surface_z_m) - depth_m * (1.0 - np.exp(-t / 0.2))
    eps = np.asarray(tissue.surface_z_m) - z
    eps_dot = np.gradient(eps, t)
    f = hunt_crossley_force(eps, eps_dot, tissue.kappa, tissue.lam, phantom.beta)
    rng = np.random.default_rng(0)
    return pd.DataFrame(
        {
            "t_s": t,
            "x_m": x,
            "y_m": y,
            "z_m": z,
            "force_sensor_z_N": -(f + 0.05 * rng.standard_normal(t.size)),
        }
    )


@pytest.mark.parametrize("method", ["rls", "ekf"])
def test_a_simulated_scan_is_scored_against_the_true_kappa(method):
    phantom = load_phantom("synthetic")
    df = _hc_scan(phantom)
    _, kappa, summary = replay_simulated_scan(
        df, phantom, OnlineEstimatorParams(method=method)
    )
    assert kappa.shape == (len(df),)
    assert summary["kappa_rel_err_median"] < 0.05
    # A wrong truth is seen as wrong: the score is not the estimator's own.
    scaled = _hc_scan(phantom)
    scaled["force_sensor_z_N"] *= 1.5
    _, _, wrong = replay_simulated_scan(
        scaled, phantom, OnlineEstimatorParams(method=method)
    )
    assert wrong["kappa_rel_err_median"] > 0.3


@pytest.mark.realdata
def test_the_stage_scores_the_real_logs_and_draws_its_figure(tmp_path, data_dir):
    result = reproduce(
        ReproduceOptions(out_dir=tmp_path, data_dir=data_dir, stages=("online",))
    )
    summaries = result.results["online"]["summaries"]
    assert "palpation/test_soft_2hz [rls]" in summaries
    assert "experiments/test_tracking5 [ekf]" in summaries
    assert summaries["palpation/test_soft_2hz [rls]"]["kappa_rel_err_median"] < 0.05
    assert (tmp_path / "figures" / "online_estimation.png").is_file()


def test_the_stage_replays_this_runs_simulated_palpation_bag(tmp_path):
    """Quick mode simulates a 2.5 Hz palpation (offline_sim) and writes it
    as the rig's bag; the online stage replays that bag as estimate-online
    would, scored against its own whole-log fit. No real data needed."""
    out = tmp_path / "run"
    result = reproduce(
        ReproduceOptions(
            out_dir=out,
            quick=True,
            phantom="synthetic",
            stages=("offline_sim", "online"),
        )
    )
    assert (out / "logs" / "palpation_sim_2.5hz_bag" / "metadata.yaml").is_file()
    summaries = result.results["online"]["summaries"]
    for method in ("rls", "ekf"):
        s = summaries[f"simulated palpation 2.5 Hz (synthetic) [{method}]"]
        assert s["kappa_corr"] != s["kappa_corr"]  # NaN: one reference value.
        assert s["convergence_s"] <= 2.0 and s["kappa_rel_err_median"] <= 0.05
