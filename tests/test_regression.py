"""Regression on logged signals: golden metrics of the default runs.

Each case runs a default scenario (short), reduces its logs to metrics and
compares them with ``tests/golden/<case>.json``, which stores for every
metric its value, an absolute and a relative tolerance, and why that
tolerance. A change that alters the behaviour fails with the list of metrics
that moved, by how much, and the allowed band. The comparison is
|new - golden| <= atol + rtol * |golden| (not bit-exact: the tolerances
absorb floating-point differences across machines and solver versions).

To accept a deliberate change of behaviour, regenerate the goldens and commit
them with the change that explains it::

    VIC_DRAKE_UPDATE_GOLDEN=1 python -m pytest tests/test_regression.py

(the tolerances and reasons are kept; only the values are rewritten).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

GOLDEN_DIR = Path(__file__).resolve().parent / "golden"
UPDATE = os.environ.get("VIC_DRAKE_UPDATE_GOLDEN") == "1"

# Tolerances per metric family: (atol, rtol, why).
TOL_FIT_RESIDUAL = (
    0.0,
    0.02,
    "relative residual of a linear least-squares fit on fixed "
    "data: deterministic up to float error; 2 % catches any change of the "
    "fit, the contact selection or the derivative filter",
)
TOL_LAG = (0.002, 0.0, "sensor lag from a grid search refined in 1 sample (2 ms)")
TOL_PARAM = (0.0, 0.02, "kappa, lambda of the fit: 2 %, as the residuals")
TOL_BETA = (
    0.01,
    0.0,
    "best beta of the sweep, refined to 1e-4; 0.01 allows solver noise",
)
TOL_FORCE = (
    0.1,
    0.03,
    "forces of a closed-loop simulation with seeded noise: 0.1 N + 3 % "
    "absorbs integrator/solver differences across platforms; a change of a "
    "controller gain or reference moves them more",
)
TOL_PEN = (0.0003, 0.05, "penetration: 0.3 mm + 5 % (the map lookup and the FDCC lag)")
TOL_STIFF = (5.0, 0.03, "stiffness from the QP: 5 N/m + 3 %")
TOL_TANK = (0.002, 0.0, "tank energy, J: 2 mJ")
TOL_POWER = (0.005, 0.0, "tank power, W: 5 mW (the valve's limit is 100 mW)")
TOL_FRACTION = (0.05, 0.0, "fraction of samples: 5 points")


def compare_to_golden(case: str, metrics: dict, tolerances: dict) -> None:
    """Asserts metrics match tests/golden/<case>.json (or rewrites it)."""
    path = GOLDEN_DIR / f"{case}.json"
    if UPDATE or not path.exists():
        if not UPDATE:
            pytest.fail(
                f"golden {path} missing; generate it with VIC_DRAKE_UPDATE_GOLDEN=1"
            )
        doc = {
            "case": case,
            "how": "tests/test_regression.py; regenerate with VIC_DRAKE_UPDATE_GOLDEN=1",
            "metrics": {
                k: {
                    "value": _plain(v),
                    "atol": tolerances[k][0],
                    "rtol": tolerances[k][1],
                    "why": tolerances[k][2],
                }
                for k, v in metrics.items()
            },
        }
        path.write_text(json.dumps(doc, indent=2) + "\n")
        pytest.skip(f"golden {path.name} rewritten")
    golden = json.loads(path.read_text())["metrics"]
    moved = []
    for name, g in golden.items():
        if name not in metrics:
            moved.append(f"{name}: missing from the new run")
            continue
        new, old = metrics[name], g["value"]
        if isinstance(new, float) and math.isnan(new):
            new = None  # No value (e.g. the tank of CS and CF): null in the golden.
        if isinstance(old, bool) or isinstance(new, bool):
            if bool(new) != bool(old):
                moved.append(f"{name}: {old} -> {new}")
            continue
        if old is None or new is None or not math.isfinite(new):
            if old != new:
                moved.append(f"{name}: {old} -> {new}")
            continue
        band = g["atol"] + g["rtol"] * abs(old)
        if abs(new - old) > band:
            moved.append(
                f"{name}: {old:.6g} -> {new:.6g} (moved {new - old:+.3g}, allowed "
                f"+-{band:.3g}: {g['why']})"
            )
    assert not moved, f"{case}: behaviour changed:\n  " + "\n  ".join(moved)


def _plain(v):
    if isinstance(v, (np.bool_, bool)):
        return bool(v)
    if isinstance(v, (np.integer, int)):
        return int(v)
    if v is None or math.isnan(v):
        return None
    return float(v)


@pytest.mark.realdata
def test_golden_offline_real(data_dir):
    """Table I on the 2.5 Hz palpation log."""
    from vic_drake.estimation.palpation import PalpationData, compare_models
    from vic_drake.realdata import read_bag

    data = PalpationData.from_frame(read_bag(data_dir / "palpation" / "test_soft_25hz"))
    c = compare_models(data, (1.5, 1.35, 1.1))
    metrics = {
        "lag_s": c.lag_s,
        "kelvin_voigt_relative": c.kelvin_voigt.relative,
        **{f"hc_{b:g}_relative": f.relative for b, f in c.hunt_crossley.items()},
        "hc_1.35_kappa": c.hunt_crossley[1.35].kappa,
        "hc_1.35_lambda": c.hunt_crossley[1.35].lam,
        "best_beta": c.best_beta,
    }
    tol = {
        "lag_s": TOL_LAG,
        "best_beta": TOL_BETA,
        "hc_1.35_kappa": TOL_PARAM,
        "hc_1.35_lambda": TOL_PARAM,
    }
    compare_to_golden(
        "offline_real_25hz", metrics, {k: tol.get(k, TOL_FIT_RESIDUAL) for k in metrics}
    )


def test_golden_simulated_palpation():
    """A 4 s palpation simulated on the synthetic chest, fitted at beta = 1.35."""
    from vic_drake.estimation.palpation import PalpationData, fit_hunt_crossley, shift
    from vic_drake.experiments import CampaignParams, simulate_palpations
    from vic_drake.systems.indenter import PalpationParams
    from vic_drake.tissue import load_phantom

    phantom = load_phantom("synthetic")
    params = CampaignParams(palpation=PalpationParams(duration_s=4.0))
    x, y = np.array([-0.05]), np.array([-0.36])
    truth = phantom.sample(x, y)
    (rec,) = simulate_palpations(
        x,
        y,
        surface_z=truth.surface_z_m,
        kappa=truth.kappa,
        lam=truth.lam,
        beta=phantom.beta,
        params=params,
        seed=0,
    )
    data = PalpationData(
        t_s=rec.t_s,
        z_m=rec.z_m,
        force_N=rec.force_N,
        surface_z_m=float(truth.surface_z_m[0]),
    )
    lag = params.sensor.lag_samples / params.sensor.rate_hz
    fit = fit_hunt_crossley(shift(data, lag), 1.35)
    metrics = {
        "kappa_over_truth": fit.kappa / float(truth.kappa[0]),
        "lambda_over_truth": fit.lam / float(truth.lam[0]),
        "relative_residual": fit.relative,
        "peak_force_N": float(np.max(rec.force_N)),
    }
    tol = {
        "kappa_over_truth": TOL_PARAM,
        "lambda_over_truth": TOL_PARAM,
        "relative_residual": TOL_FIT_RESIDUAL,
        "peak_force_N": TOL_FORCE,
    }
    compare_to_golden("palpation_sim", metrics, tol)


def test_compare_to_golden_names_the_moved_metric(tmp_path, monkeypatch):
    import tests.test_regression as mod

    monkeypatch.setattr(mod, "GOLDEN_DIR", tmp_path)
    monkeypatch.setattr(mod, "UPDATE", False)
    (tmp_path / "c.json").write_text(
        json.dumps(
            {
                "metrics": {
                    "force_N": {"value": 7.0, "atol": 0.1, "rtol": 0.0, "why": "w"},
                    "ok": {"value": True, "atol": 0, "rtol": 0, "why": "w"},
                }
            }
        )
    )
    compare_to_golden("c", {"force_N": 7.05, "ok": True}, {})
    with pytest.raises(AssertionError, match=r"force_N: 7 -> 7.3 \(moved \+0.3"):
        compare_to_golden("c", {"force_N": 7.3, "ok": True}, {})
    with pytest.raises(AssertionError, match="ok: True -> False"):
        compare_to_golden("c", {"force_N": 7.0, "ok": False}, {})


SCAN_TOLERANCES = {
    "force_mean_N": TOL_FORCE,
    "force_rmse_N": TOL_FORCE,
    "force_range_N": TOL_FORCE,
    "peak_force_N": TOL_FORCE,
    "final_force_N": TOL_FORCE,
    "lifted_off": (0, 0, "a boolean outcome"),
    "penetration_off_ribs_median_m": TOL_PEN,
    "penetration_error_off_ribs_median_m": TOL_PEN,
    "force_on_ribs_p99_N": TOL_FORCE,
    "n_contact_losses": (
        0,
        0,
        "count of contact losses (analysis.contact.MIN_CONTACT_LOSS_S)",
    ),
    "fraction_at_k_min_during_loss": TOL_FRACTION,
    "tank_min_J": TOL_TANK,
    "tank_power_min_W": TOL_POWER,
    "stiffness_z_max_N_per_m": TOL_STIFF,
}


def _scan_case(controller: str, *, disturbed: bool, duration_s: float) -> dict:
    from vic_drake.analysis.claims import scan_metrics
    from vic_drake.experiments import run_scan
    from vic_drake.reproduce import scan_limits, scan_scenario

    scenario = scan_scenario(
        controller, disturbed=disturbed, phantom_kind="synthetic", quick=True
    )
    result = run_scan(scenario, duration_s=duration_s)
    m = scan_metrics(result.df, limits=scan_limits(scenario))
    return {k: m[k] for k in SCAN_TOLERANCES if k in m}


def test_golden_scan_vs_vf_nominal():
    """6 s of the default VS-VF scan on the synthetic chest (approach + 3.5 s of
    scanning): force tracking, penetration, stiffness, tank."""
    metrics = _scan_case("vs-vf", disturbed=False, duration_s=6.0)
    compare_to_golden(
        "scan_vs_vf_nominal_6s", metrics, {k: SCAN_TOLERANCES[k] for k in metrics}
    )


@pytest.mark.slow
@pytest.mark.parametrize("controller", ["vs-vf", "cs", "cf"])
def test_golden_scan_disturbance(controller):
    """The quick disturbance scan (one lift) of each disturbed controller."""
    metrics = _scan_case(controller, disturbed=True, duration_s=None)
    compare_to_golden(
        f"scan_{controller.replace('-', '_')}_disturbance_quick",
        metrics,
        {k: SCAN_TOLERANCES[k] for k in metrics},
    )
