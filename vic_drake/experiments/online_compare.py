"""Closed loop: VS-VF on the true map, on a wrong map, and with online estimates.

:func:`online_comparison` runs the VS-VF scan of one phantom three (four)
ways and scores each against the TRUE tissue, not against the controller's
own reference (a controller on a wrong map tracks its own wrong reference
well):

- "true_map": the phantom's own map;
- "wrong_map_+30" and "wrong_map_-30": kappa x 1.3 / x 0.7, surface + 2 mm
  (``variations.map_errors``);
- "online": ``stiffness_source: online``, the estimator seeded with its
  prior (no map).

Scores over the scan window (:func:`vic_drake.analysis.contact.scan_window`):

- ``force_rmse_true_N``: RMS of sensor z force minus the true VS-VF
  reference -kappa_true(x, y) eps_d^beta (the elastic part: the reference
  the controller would use with a perfect map at rest, capped at
  F_min,z as the QP caps it);
- ``force_rmse_own_N``: RMS against the controller's own F_ref;
- ``penetration_err_mm``: median |true penetration - eps_d| (the true
  surface under the probe minus the tip height);
- ``rib_p99_force_N``: 99th percentile of the pressing force where the
  true kappa exceeds the rib threshold.
"""

from __future__ import annotations

import copy

import numpy as np

from vic_drake.analysis.contact import pressing_force_N, scan_window
from vic_drake.analysis.scan_metrics import RIB_KAPPA_THRESHOLD, force_rmse_N
from vic_drake.experiments.scan_run import run_scan
from vic_drake.scenario import Scenario

#: The runs of the comparison: name -> (stiffness_source, kappa_scale,
#: surface_offset_m, online_surface). "online" reads no map at all;
#: "online_map_surface" takes only the surface from the true map and
#: "online_wrong_surface" from the map 2 mm too high (kappa, lam online).
COMPARISON_RUNS = {
    "true_map": ("map", 1.0, 0.0, "estimated"),
    "wrong_map_+30": ("map", 1.3, 0.002, "estimated"),
    "wrong_map_-30": ("map", 0.7, 0.002, "estimated"),
    "online": ("online", 1.0, 0.0, "estimated"),
    "online_map_surface": ("online", 1.0, 0.0, "map"),
    "online_wrong_surface": ("online", 1.0, 0.002, "map"),
}


def comparison_scenario(base: Scenario, run: str) -> Scenario:
    """The base VS-VF scenario set up for one run of :data:`COMPARISON_RUNS`."""
    source, kappa_scale, offset, surface = COMPARISON_RUNS[run]
    s = copy.deepcopy(base)
    s.name = f"{base.name}_{run}"
    s.stiffness_source = source
    s.online_surface = surface
    if surface == "map":  # Trust the map's surface: no surface state.
        s.online_estimator.surface_walk_m_per_sqrt_s = 0.0
    s.variations.map_errors.kappa_scale = kappa_scale
    s.variations.map_errors.surface_offset_m = offset
    return s.validate()


def score_against_truth(df, phantom, scenario: Scenario) -> dict:
    """The scores of the module docstring for one simulated scan."""
    window = scan_window(df)
    x, y, z = (df[c].to_numpy(float) for c in ("x_m", "y_m", "z_m"))
    tissue = phantom.sample(x, y)
    ref = scenario.controller.reference
    # The VS-VF reference on the true tissue, capped by F_min,z as the QP
    # caps it (sensor convention: pressing is negative).
    f_true = np.maximum(
        -np.asarray(tissue.kappa) * ref.eps_d_m**phantom.beta, ref.force_min_z_N
    )
    err = df["force_sensor_z_N"].to_numpy(float) - f_true
    contact = df["in_contact"].to_numpy(float) > 0.5
    sel = window & contact & np.isfinite(err)
    pen = np.asarray(tissue.surface_z_m) - z - df["phantom_lift_m"].to_numpy(float)
    rib = window & (np.asarray(tissue.kappa) > RIB_KAPPA_THRESHOLD)
    pressing = pressing_force_N(df)
    return {
        "force_rmse_true_N": float(np.sqrt(np.mean(err[sel] ** 2)))
        if sel.any()
        else np.nan,
        "force_rmse_own_N": force_rmse_N(df),
        "penetration_err_mm": float(np.median(np.abs(pen[sel] - ref.eps_d_m)) * 1e3)
        if sel.any()
        else np.nan,
        "rib_p99_force_N": float(np.percentile(pressing[rib], 99))
        if rib.any()
        else np.nan,
    }


def online_comparison(
    base: Scenario,
    *,
    phantom,
    runs=tuple(COMPARISON_RUNS),
    duration_s=None,
    progress=None,
) -> dict:
    """{run: scores} for each run (see the module docstring)."""
    out = {}
    for run in runs:
        s = comparison_scenario(base, run)
        result = run_scan(s, phantom=phantom, duration_s=duration_s, progress=progress)
        out[run] = score_against_truth(result.df, phantom, s)
    return out


__all__ = [
    "COMPARISON_RUNS",
    "comparison_scenario",
    "online_comparison",
    "score_against_truth",
]
