"""Campaign statistics against closed forms and hand-made rows."""

import math

import pandas as pd
import pytest

from vic_drake.experiments.campaign.stats import (
    factor_effects,
    paired_arms,
    per_controller,
    wilson_interval,
    worst_runs,
)


def test_wilson_interval_closed_form_and_edges():
    # n = 10, k = 0: upper bound z^2 / (n + z^2).
    z = 1.959963984540054
    lo, hi = wilson_interval(0, 10)
    assert lo == 0.0 and hi == pytest.approx(z * z / (10 + z * z))
    lo, hi = wilson_interval(10, 10)
    assert hi == pytest.approx(1.0) and lo == pytest.approx(10 / (10 + z * z))
    lo, hi = wilson_interval(50, 100)  # Symmetric about 1/2.
    assert lo + hi == pytest.approx(1.0) and hi - lo == pytest.approx(0.1922, abs=1e-3)
    assert all(math.isnan(v) for v in wilson_interval(0, 0))
    # Exact ends for every n (n = 12 left a 3e-17 residue).
    for n in range(1, 200):
        assert wilson_interval(0, n)[0] == 0.0 and wilson_interval(n, n)[1] == 1.0


def _rows():
    return pd.DataFrame(
        {
            "run_id": [f"run_{i:05d}" for i in range(6)],
            "index": range(6),
            "status": ["ok", "ok", "ok", "ok", "nan", "error"],
            "error": ["", "", "", "", "non-finite", "boom"],
            "factor.controller": ["cs", "cs", "cs", "vs-vf", "vs-vf", "vs-vf"],
            "factor.amp": [0.005, 0.010, 0.015, 0.005, 0.010, 0.015],
            "peak_force_N": [10.0, 16.0, 20.0, 8.0, 9.0, float("nan")],
            "contact_loss_s": [0.0, 0.1, 0.3, 0.0, 0.0, float("nan")],
            "tank_min_J": [0.5, 0.5, 0.5, 0.45, 0.41, float("nan")],
        }
    )


def test_per_controller_counts_scored_runs_only():
    pc = per_controller(_rows(), force_limit_N=15.0)
    assert pc["cs"]["runs"] == 3 and pc["cs"]["exceed_prob"] == pytest.approx(2 / 3)
    assert pc["cs"]["exceed_prob_ci95"] == list(wilson_interval(2, 3))
    assert pc["vs-vf"]["runs"] == 3 and pc["vs-vf"]["exceed_prob"] == 0.0
    assert pc["vs-vf"]["tank_min_J"] == 0.41
    assert pc["cs"]["peak_force_N_p50"] == 16.0 and pc["cs"]["peak_force_N_max"] == 20.0


def test_factor_effects_and_worst_runs():
    effects = factor_effects(_rows())
    cs = next(e for e in effects if e["controller"] == "cs")
    assert cs["spearman"] == pytest.approx(1.0)
    worst = worst_runs(_rows(), n=3)
    assert list(worst["run_id"]) == ["run_00005", "run_00004", "run_00002"]


def _paired_rows():
    """Four rounds of two arms; round 3's second run failed."""
    arm = ["map", "online"] * 4
    return pd.DataFrame(
        {
            "index": range(8),
            "status": ["ok"] * 7 + ["error"],
            "factor.controller": arm,
            "peak_force_N": [9.0, 9.5, 10.0, 9.0, 16.0, 14.0, 9.0, float("nan")],
            "contact_loss_s": [0.0, 0.5, 0.0, 0.2, 0.0, 0.0, 0.3, 0.0],
        }
    )


def test_paired_arms_compare_run_for_run():
    (c,) = paired_arms(_paired_rows(), 2, 15.0)
    assert (c["first"], c["second"], c["pairs"]) == ("map", "online", 3)
    # Differences online - map over rounds 0-2: +0.5, -1.0, -2.0.
    assert c["peak_force_diff_N_p50"] == pytest.approx(-1.0)
    assert c["peak_force_diff_N_p10"] == pytest.approx(-1.8)
    assert c["peak_force_diff_N_p90"] == pytest.approx(0.2)
    # Contact loss: online alone in rounds 0 and 1; exact McNemar p = 0.5.
    assert c["contact_loss"] == {
        "both": 0,
        "only_first": 0,
        "only_second": 2,
        "mcnemar_p": pytest.approx(0.5),
    }
    assert c["exceedance"]["only_first"] == 1 and c["exceedance"]["only_second"] == 0


def test_paired_arms_need_a_grid_of_two_or_more():
    assert paired_arms(_paired_rows(), 0, 15.0) == []
    assert paired_arms(_paired_rows().iloc[:0], 2, 15.0) == []
