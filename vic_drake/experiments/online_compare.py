"""Closed loop: VS-VF on the true map, on a wrong map, and with online estimates.

:func:`online_comparison` runs the VS-VF scan of one phantom several ways
and scores each against the TRUE tissue, not against the controller's own
reference (a controller on a wrong map tracks its own wrong reference
well):

- "true_map": the phantom's own map;
- "wrong_map_+30" and "wrong_map_-30": kappa x 1.3 / x 0.7, surface + 2 mm
  (``variations.map_errors``);
- "online": ``stiffness_source: online``, the estimator seeded with its
  prior (no map);
- "online_map_surface", "online_wrong_surface": online kappa, lam on the
  true map's surface / on the map's surface 2 mm high;
- "..._dither": the same with the penetration dither on
  (:data:`DITHER_M` at :data:`DITHER_HZ`); "online_dither" also takes its
  surface from the tissue's slope under the dithered tip
  (``online_estimator.surface_from_slope``, no EKF surface state) in the
  fit's "direct" mode (``slope_kappa_mode``: kappa from the fit, held,
  softened towards the force at the held surface while K_z is saturated);
  "online_dither_tracker" is the same in the fit's "tracker" mode (the fit's
  surface through a slow filter); both fits take the dither as their
  instrument (``slope_instrument``), "online_dither_ls" and
  "online_dither_tracker_ls" are the same two by least squares. The map
  runs with the dither show what the dither alone costs.

``main``'s ``--force-min-z`` sets VS-VF's F_min,z of every run (the rig's
-9 N binds on the ribs in every run, so their p99 force there is the
bound's; docs/decisions.md, "The closed loop at the QP's own force bound").
Given several ``--dither-hz``, the dithered runs are made at each
(:mod:`vic_drake.experiments.online_sweep`; the same command is ``vic-drake
compare-online``): a closed loop with an estimator in it moves by 0.1-0.2 N
of force RMSE from one dither frequency to the next, so one run's margin
over another is no evidence; the table then shows each score's mean and
range, and ``--against RUN`` counts the frequencies at which each run is
below RUN.

Scores over the scan window (:func:`vic_drake.analysis.contact.scan_window`):

- ``force_rmse_true_N``: RMS of sensor z force minus the true VS-VF
  reference -kappa_true(x, y) eps_d^beta (the elastic part: the reference
  the controller would use with a perfect map at rest, capped at
  F_min,z as the QP caps it). The dither is NOT taken out: its force swing
  counts as error, so a dithered run pays for it here;
- ``force_rmse_dithered_truth_N``: the same against the true reference
  with the run's own dither (eps_d(t), and F_min,z(t) as the dithered
  references lower it): the error beyond the dither (equal to the above
  without the dither);
- ``dither_rms_N``: RMS of the dither's own part of that reference (true
  dithered minus true undithered; 0 without the dither);
- ``force_rmse_own_N``: RMS against the controller's own F_ref;
- ``penetration_err_mm``: median |true penetration - eps_d| (the true
  surface under the probe minus the tip height; eps_d without the dither);
- ``kappa_rel_err_median``: median |kappa_used / kappa_true - 1|, with
  kappa_used = -F_ref,z / eps_d(t)^beta the stiffness the controller's
  reference was made with (F_ref,z is logged before the cap; its damping
  term averages out over a dither cycle): the online estimate for the
  online runs, the map's kappa (x 1.3 for "wrong_map_+30") for the others;
- ``rib_p99_force_N``: 99th percentile of the pressing force where the
  true kappa exceeds the rib threshold;
- ``tank_min_J``: the lowest tank energy over the scan window (the tank
  must stay >= T_min: the dither varies K, which the tank pays for).
"""

from __future__ import annotations

import copy
from typing import NamedTuple

import numpy as np

from vic_drake.analysis.contact import pressing_force_N, scan_window
from vic_drake.analysis.scan_metrics import RIB_KAPPA_THRESHOLD, force_rmse_N
from vic_drake.experiments.scan_run import run_scan
from vic_drake.scenario import Scenario

#: The comparison's dither of the desired penetration: amplitude, m, and
#: frequency, Hz (docs/decisions.md, "Closed loop with a penetration dither").
DITHER_M = 3e-4
DITHER_HZ = 3.0


class ComparisonRun(NamedTuple):
    """One run of the comparison: the stiffness source ("map" | "online"),
    the map's error (kappa scale, surface offset, m), the online estimator's
    surface ("estimated" | "map"), whether the dither is on and, for the
    dithered online runs, the slope fit's ``slope_kappa_mode`` and
    ``slope_instrument``."""

    source: str
    kappa_scale: float
    surface_offset_m: float
    online_surface: str
    dither: bool
    slope_kappa_mode: str = "tracker"
    slope_instrument: str = "dither"


#: The runs of the comparison. "online" reads no map at all;
#: "online_map_surface" takes only the surface from the true map and
#: "online_wrong_surface" from the map 2 mm too high (kappa, lam online).
COMPARISON_RUNS = {
    "true_map": ComparisonRun("map", 1.0, 0.0, "estimated", False),
    "wrong_map_+30": ComparisonRun("map", 1.3, 0.002, "estimated", False),
    "wrong_map_-30": ComparisonRun("map", 0.7, 0.002, "estimated", False),
    "online": ComparisonRun("online", 1.0, 0.0, "estimated", False),
    "online_map_surface": ComparisonRun("online", 1.0, 0.0, "map", False),
    "online_wrong_surface": ComparisonRun("online", 1.0, 0.002, "map", False),
    "true_map_dither": ComparisonRun("map", 1.0, 0.0, "estimated", True),
    "wrong_map_+30_dither": ComparisonRun("map", 1.3, 0.002, "estimated", True),
    "wrong_map_-30_dither": ComparisonRun("map", 0.7, 0.002, "estimated", True),
    "online_dither": ComparisonRun("online", 1.0, 0.0, "estimated", True, "direct"),
    "online_dither_tracker": ComparisonRun("online", 1.0, 0.0, "estimated", True),
    "online_dither_ls": ComparisonRun(
        "online", 1.0, 0.0, "estimated", True, "direct", "none"
    ),
    "online_dither_tracker_ls": ComparisonRun(
        "online", 1.0, 0.0, "estimated", True, slope_instrument="none"
    ),
}

#: The runs of the comparison before the dither (issue 12's first table).
UNDITHERED_RUNS = tuple(name for name, run in COMPARISON_RUNS.items() if not run.dither)


def comparison_scenario(
    base: Scenario, run: str, *, dither_hz: float = DITHER_HZ
) -> Scenario:
    """The base VS-VF scenario set up for one run of :data:`COMPARISON_RUNS`.

    ``dither_hz``: the dither's frequency in the dithered runs (a
    VicDrakeError from the scenario's validation if the controller cannot
    take it).
    """
    spec = COMPARISON_RUNS[run]
    s = copy.deepcopy(base)
    s.name = f"{base.name}_{run}"
    s.stiffness_source = spec.source
    s.online_surface = spec.online_surface
    if spec.online_surface == "map":  # Trust the map's surface: no surface state.
        s.online_estimator.surface_walk_m_per_sqrt_s = 0.0
    s.variations.map_errors.kappa_scale = spec.kappa_scale
    s.variations.map_errors.surface_offset_m = spec.surface_offset_m
    if spec.dither:
        s.controller.reference.penetration_dither_m = DITHER_M
        s.controller.reference.penetration_dither_hz = dither_hz
        if spec.source == "online":  # The surface from the slope, no EKF surface state.
            s.online_estimator.surface_from_slope = True
            s.online_estimator.surface_walk_m_per_sqrt_s = 0.0
            s.online_estimator.slope_kappa_mode = spec.slope_kappa_mode
            s.online_estimator.slope_instrument = spec.slope_instrument
    return s.validate()


def true_references(df, phantom, scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """(undithered, dithered) true VS-VF z references of every row, N.

    -kappa_true(x, y) eps_d^beta capped at F_min,z, and the same with the
    run's dither: eps_d(t) and F_min,z(t) as
    :func:`vic_drake.control.references.force_references` form them.
    """
    x, y = (df[c].to_numpy(float) for c in ("x_m", "y_m"))
    kappa = np.asarray(phantom.sample(x, y).kappa)
    return _true_references(
        kappa, desired_penetrations(df, scenario), scenario, phantom.beta
    )


def _true_references(kappa, eps_d, scenario: Scenario, beta: float):
    """:func:`true_references` from the true kappa and eps_d(t) of every row."""
    ref = scenario.controller.reference
    plain = np.maximum(-kappa * ref.eps_d_m**beta, ref.force_min_z_N)
    if ref.penetration_dither_m == 0.0:
        return plain, plain
    f_min = ref.force_min_z_N * np.minimum(1.0, (eps_d / ref.eps_d_m) ** beta)
    return plain, np.maximum(-kappa * eps_d**beta, f_min)


def desired_penetrations(df, scenario: Scenario) -> np.ndarray:
    """eps_d(t) of every row, m: eps_d with the run's dither
    (:func:`vic_drake.control.references.desired_penetration`)."""
    ref = scenario.controller.reference
    t = df["t_s"].to_numpy(float)
    return ref.eps_d_m + ref.penetration_dither_m * np.sin(
        2.0 * np.pi * ref.penetration_dither_hz * t
    )


def _rms(values: np.ndarray, sel: np.ndarray) -> float:
    return float(np.sqrt(np.mean(values[sel] ** 2))) if sel.any() else np.nan


def score_against_truth(df, phantom, scenario: Scenario) -> dict:
    """The scores of the module docstring for one simulated scan."""
    window = scan_window(df)
    x, y, z = (df[c].to_numpy(float) for c in ("x_m", "y_m", "z_m"))
    tissue = phantom.sample(x, y)
    kappa_true = np.asarray(tissue.kappa)
    eps_d = desired_penetrations(df, scenario)
    ref = scenario.controller.reference
    # The VS-VF reference on the true tissue (sensor convention: pressing
    # is negative).
    f_true, f_dithered = _true_references(kappa_true, eps_d, scenario, phantom.beta)
    force = df["force_sensor_z_N"].to_numpy(float)
    err = force - f_true
    contact = df["in_contact"].to_numpy(float) > 0.5
    sel = window & contact & np.isfinite(err)
    pen = np.asarray(tissue.surface_z_m) - z - df["phantom_lift_m"].to_numpy(float)
    rib = window & (kappa_true > RIB_KAPPA_THRESHOLD)
    pressing = pressing_force_N(df)
    # The stiffness the controller's reference was made with: F_ref,z is
    # logged before the F_min,z cap, so -F_ref,z / eps_d(t)^beta is the
    # controller's kappa (its damping term lam eps_dot included, which
    # averages out over a dither cycle).
    kappa_used = -df["force_ref_z_N"].to_numpy(float) / eps_d**phantom.beta
    kappa_err = np.abs(kappa_used / kappa_true - 1.0)
    return {
        "force_rmse_true_N": _rms(err, sel),
        "force_rmse_dithered_truth_N": _rms(force - f_dithered, sel),
        "dither_rms_N": _rms(f_dithered - f_true, sel),
        "force_rmse_own_N": force_rmse_N(df),
        "penetration_err_mm": float(np.median(np.abs(pen[sel] - ref.eps_d_m)) * 1e3)
        if sel.any()
        else np.nan,
        "kappa_rel_err_median": float(np.median(kappa_err[sel]))
        if sel.any()
        else np.nan,
        "rib_p99_force_N": float(np.percentile(pressing[rib], 99))
        if rib.any()
        else np.nan,
        "tank_min_J": float(df["tank_energy_J"].to_numpy(float)[window].min())
        if window.any()
        else np.nan,
    }


def online_comparison(
    base: Scenario,
    *,
    phantom,
    runs=UNDITHERED_RUNS,
    duration_s=None,
    progress=None,
    dither_hz: float = DITHER_HZ,
) -> dict:
    """{run: scores} for each run (see the module docstring), one at a time
    (``dither_hz``: as :func:`comparison_scenario`)."""
    out = {}
    for run in runs:
        s = comparison_scenario(base, run, dither_hz=dither_hz)
        result = run_scan(s, phantom=phantom, duration_s=duration_s, progress=progress)
        out[run] = score_against_truth(result.df, phantom, s)
    return out


#: The table's scores: (key, column title, decimals, what it is). All are
#: over the scan window.
_COLUMNS = (
    (
        "force_rmse_true_N",
        "force RMSE vs truth N",
        3,
        "sensor z force against the reference a perfect map gives "
        "(-kappa_true eps_d^beta); a dither's swing counts as error",
    ),
    (
        "force_rmse_dithered_truth_N",
        "vs dithered truth N",
        3,
        "the same against the true reference with the run's own dither, the "
        "error beyond the dither",
    ),
    (
        "dither_rms_N",
        "dither RMS N",
        3,
        "the dither's own part of that reference (0 without a dither)",
    ),
    (
        "penetration_err_mm",
        "penetration err mm",
        2,
        "median |true penetration - eps_d|",
    ),
    (
        "kappa_rel_err_median",
        "kappa err (median)",
        3,
        "median |kappa the reference used / kappa_true - 1|",
    ),
    (
        "rib_p99_force_N",
        "p99 force on ribs N",
        2,
        "p99 of the pressing force where the true kappa is a rib's",
    ),
    (
        "tank_min_J",
        "tank min J",
        3,
        "the lowest tank energy (T_min is the floor)",
    ),
)

#: One line per column of :func:`comparison_table`, printed under it.
COLUMN_LEGEND = tuple(f"{title}: {meaning}" for _, title, _, meaning in _COLUMNS) + (
    "all over the scan window",
)


def comparison_table(scores: dict) -> str:
    """The scores as a markdown table, one row a run: ``{run: scores}``, or
    ``{run: [scores, ...]}`` from
    :func:`vic_drake.experiments.online_sweep.online_comparison_sweep`, whose
    cells are "mean (min-max)" over the frequencies (the mean alone where
    they agree to the digits shown)."""
    lines = [
        "| run | " + " | ".join(c[1] for c in _COLUMNS) + " |",
        "|---|" + "---|" * len(_COLUMNS),
    ]
    for run, sc in scores.items():
        many = sc if isinstance(sc, list) else [sc]
        cells = []
        for key, _, digits, _ in _COLUMNS:
            values = np.array([one[key] for one in many], dtype=float)
            cell = f"{np.mean(values):.{digits}f}"
            low, high = f"{np.min(values):.{digits}f}", f"{np.max(values):.{digits}f}"
            if low != high:  # (A run made once, without the dither: one value.)
                cell += f" ({low}-{high})"
            cells.append(cell)
        lines.append(f"| {run} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> None:
    """``python -m vic_drake.experiments.online_compare``: the comparison's
    command line (:func:`vic_drake.experiments.online_sweep.main`; also
    ``vic-drake compare-online``)."""
    from vic_drake.experiments.online_sweep import main as sweep_main

    sweep_main(argv)


__all__ = [
    "COLUMN_LEGEND",
    "COMPARISON_RUNS",
    "ComparisonRun",
    "DITHER_HZ",
    "DITHER_M",
    "UNDITHERED_RUNS",
    "comparison_scenario",
    "comparison_table",
    "desired_penetrations",
    "main",
    "online_comparison",
    "score_against_truth",
    "true_references",
]

if __name__ == "__main__":
    main()
