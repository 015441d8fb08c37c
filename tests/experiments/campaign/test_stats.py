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
    # Three runs of cs: too few for a rank correlation (MIN_EFFECT_RUNS).
    effects = factor_effects(_rows())
    cs = next(e for e in effects if e["controller"] == "cs")
    assert cs == {"factor": "amp", "controller": "cs", "kind": "too_few", "runs": 3}
    five = pd.DataFrame(
        {
            "status": ["ok"] * 6,
            "factor.controller": ["cs"] * 6,
            "factor.amp": [0.015, 0.005, 0.010, 0.020, 0.0, 0.025],
            "peak_force_N": [13.0, 11.0, 12.0, 14.0, 10.0, 30.0],
        }
    )
    (cs,) = factor_effects(five)
    assert cs["kind"] == "numeric" and cs["spearman"] == pytest.approx(1.0)
    # Thirds of the amplitudes 0..0.025: <= 0.00833 and >= 0.01667.
    assert cs["low_third_median"] == pytest.approx(10.5)
    assert cs["high_third_median"] == pytest.approx(22.0)
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


def test_paired_arms_pair_within_the_other_grid_factors_cells():
    """Two grid factors (the arm, a breathing amplitude) over 3 rounds: 6
    pairs, each arm's run against the other arm's at the same amplitude. A
    failed run drops its pair alone (it had made the arms' lengths differ:
    a broadcast error and no summary)."""
    rows = []
    for index in range(12):
        rnd, cell = divmod(index, 4)
        arm, amplitude = ("cs", "vs-vf")[cell % 2], (0.005, 0.015)[cell // 2]
        rows.append(
            {
                "index": index,
                "status": "ok",
                "factor.controller": arm,
                "factor.variations.motion.breathing.amplitude_m": amplitude,
                "factor.variations.sensor_faults.noise_std_N": 0.1 * rnd,  # Drawn.
                # vs-vf 1 N above cs at the small amplitude, 3 N at the large.
                "peak_force_N": 8.0 + rnd + (arm == "vs-vf") * (1 + 2 * (cell // 2)),
                "contact_loss_s": 0.0,
            }
        )
    table = pd.DataFrame(rows)
    (c,) = paired_arms(table, 4, 15.0)
    assert c["pairs"] == 6
    assert c["peak_force_diff_N_p10"] == pytest.approx(1.0)
    assert c["peak_force_diff_N_p90"] == pytest.approx(3.0)
    table.loc[5, "status"] = "error"  # Round 1, vs-vf at the small amplitude.
    (c,) = paired_arms(table, 4, 15.0)
    assert c["pairs"] == 5
    assert c["contact_loss"]["both"] == 0


def test_paired_arms_pair_an_arm_made_by_a_field_path():
    """A grid on controller.reference.controller makes the arms as the
    controller factor does: its column holds one value per arm and is not
    part of the pair."""
    rows = pd.DataFrame(
        {
            "index": range(8),
            "status": "ok",
            "factor.controller": ["vs-cf", "vs-vf"] * 4,
            "factor.controller.reference.controller": ["vs-cf", "vs-vf"] * 4,
            "factor.variations.sensor_faults.noise_std_N": [0.1, 0.1, 0.3, 0.3] * 2,
            "peak_force_N": [7.0, 8.0] * 4,
            "contact_loss_s": 0.0,
        }
    )
    (c,) = paired_arms(rows, 2, 15.0)
    assert c["pairs"] == 4 and c["peak_force_diff_N_p50"] == pytest.approx(1.0)


def test_paired_arms_need_a_grid_of_two_or_more():
    assert paired_arms(_paired_rows(), 0, 15.0) == []
    assert paired_arms(_paired_rows().iloc[:0], 2, 15.0) == []


def _small_rows(runs_per_controller: int = 2) -> pd.DataFrame:
    """A campaign's rows with few runs per controller (as an 8-run campaign of
    the four controllers); vs-cf's first run never touched the patient."""
    names = ["cs", "cf", "vs-cf", "vs-vf"]
    n = 4 * runs_per_controller
    peaks = [6.8, 10.3, 0.0, 6.6, 5.8, 7.4, 7.8, 4.3] * runs_per_controller
    return pd.DataFrame(
        {
            "run_id": [f"run_{i:05d}" for i in range(n)],
            "index": range(n),
            "status": ["ok"] * n,
            "error": [""] * n,
            "factor.controller": names * runs_per_controller,
            "factor.amp": [0.001 * (i + 1) + 0.0001 * i * i for i in range(n)],
            "factor.mode": ["hold", "nan"] * (n // 2),
            "factor.dead": ["true"] * n,
            "peak_force_N": peaks[:n],
            "contact_loss_s": [0.0] * n,
            "tank_min_J": [float("nan")] * n,
        }
    )


def test_few_runs_per_controller_are_too_few_for_factor_effects():
    effects = factor_effects(_small_rows(2))
    # Two runs per controller: no rank correlation, no per-level medians, and
    # a numeric factor is never a list of its values as labels.
    assert {e["kind"] for e in effects} == {"too_few"}
    assert {(e["controller"], e["runs"]) for e in effects} == {
        (c, 2) for c in ("cs", "cf", "vs-cf", "vs-vf")
    }


def test_a_numeric_factor_with_two_values_is_summarised_per_value():
    """A grid or choice of two numbers: the median per value (thirds of two
    values would be the values themselves), the keys written short."""
    rows = _small_rows(3)
    # Two values only (as a grid of two), each controller's 0.005, 0.010, 0.005.
    rows["factor.amp"] = [0.005] * 4 + [0.010] * 4 + [0.005] * 4
    rows["factor.mode"] = ["hold"] * 4 + ["nan"] * 4 + ["hold"] * 4
    rows = pd.concat([rows, rows.assign(index=rows["index"] + 12)])
    effects = factor_effects(rows)
    amp = [e for e in effects if e["factor"] == "amp"]
    assert {e["kind"] for e in amp} == {"levels"}
    cs = next(e for e in amp if e["controller"] == "cs")
    assert list(cs["runs"]) == ["0.005", "0.01"] and cs["runs"] == {
        "0.005": 4,
        "0.01": 2,
    }
    mode = next(e for e in effects if e["factor"] == "mode" and e["controller"] == "cs")
    assert mode["kind"] == "levels" and mode["runs"] == {"hold": 4, "nan": 2}
    assert mode["medians"] == {"hold": 6.8, "nan": 5.8}
    dead = [e for e in effects if e["factor"] == "dead"]
    assert {e["kind"] for e in dead} == {"constant"} and dead[0]["value"] == "true"


def test_a_drawn_factor_gets_its_rank_correlation_runs_and_p():
    """Drawn values (more than three): Spearman's rho with its p and the run
    count; a zero correlation reads 0, not a 3e-17 residue."""
    n = 12
    rows = pd.DataFrame(
        {
            "index": range(n),
            "status": "ok",
            "factor.controller": "vs-vf",
            "factor.amp": [0.001 * (i + 1) for i in range(n)],
            "peak_force_N": [6.0 + 0.1 * i for i in range(n)],
            "contact_loss_s": 0.0,
        }
    )
    (e,) = factor_effects(rows)
    assert e["kind"] == "numeric" and e["runs"] == n
    assert e["spearman"] == 1.0 and e["spearman_p"] < 1e-6
    rows["peak_force_N"] = [7, 6, 6, 7, 7, 6, 6, 7, 7, 6, 6, 7]  # No trend.
    (e,) = factor_effects(rows)
    assert e["spearman"] == 0.0 and e["spearman_p"] == pytest.approx(1.0)


def test_runs_that_never_touched_the_patient_are_counted_not_dropped():
    pc = per_controller(_small_rows(2), force_limit_N=7.0)
    vs = pc["vs-cf"]
    assert vs["no_contact_runs"] == 1 and pc["cs"]["no_contact_runs"] == 0
    # The median of the runs in contact; the key of every run stays.
    assert vs["peak_force_N_p50_contact"] == 7.8
    assert vs["peak_force_N_p50"] == pytest.approx(3.9)
    # The run without contact stays in the exceedance's denominator.
    assert vs["exceed_prob"] == 0.5
