"""Writes the worked-example notebooks of vic_drake (run: python make_notebooks.py).

The notebooks are generated, not hand-edited, so that they stay small,
diff-able and consistent. Each reads the environment variable
``VIC_DRAKE_SHORT``: when it is "1" (the test suite sets it) the runs are
shortened to a few seconds of simulated time; the text and the calls are the
same. Outputs are not stored: run the notebooks to see them (README,
"Notebooks"). The plot functions of :mod:`vic_drake.reproduce.plots` return
figures that Jupyter shows as images; a figure drawn inside an ``if`` block
is shown with ``display(...)``.
"""

from __future__ import annotations

from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

HERE = Path(__file__).resolve().parent

SETUP = """\
import os

import matplotlib.pyplot as plt
import numpy as np

import vic_drake
from vic_drake.paths import has_data, resolve_data_dir

SHORT = os.environ.get("VIC_DRAKE_SHORT") == "1"  # the test suite's short mode
DATA = resolve_data_dir() if has_data() else None
print(f"vic_drake {vic_drake.__version__}; real data: {DATA}; short mode: {SHORT}")"""


def nb_tissue_estimation():
    return [
        new_markdown_cell(
            "# 1. Tissue estimation: Hunt-Crossley vs Kelvin-Voigt\n\n"
            "The paper's offline phase (Sec. II-A, III-A): a sinusoidal palpation gives "
            "penetration and force; a linear least-squares fit at fixed beta gives the "
            "Hunt-Crossley elasticity kappa and viscosity lambda. We compare the models "
            "(Table I), sweep beta and look at how the residual falls with palpation time "
            "(Fig. 3). With the paper's data we use its palpation logs; without it, a "
            "palpation simulated on the synthetic chest with Drake."
        ),
        new_code_cell(SETUP),
        new_code_cell(
            """\
from vic_drake.estimation.palpation import (
    PalpationData, compare_models, residual_vs_palpation_time, shift)

if DATA is not None:
    from vic_drake.realdata import read_bag

    data = PalpationData.from_frame(read_bag(DATA / "palpation" / "test_soft_25hz"))
    lag = None  # estimated from the log
else:
    from vic_drake.experiments import CampaignParams, simulate_palpations
    from vic_drake.systems.indenter import PalpationParams
    from vic_drake.tissue import load_phantom

    phantom = load_phantom("synthetic")
    params = CampaignParams(palpation=PalpationParams(duration_s=4.0 if SHORT else 10.0))
    truth = phantom.sample(np.array([-0.05]), np.array([-0.36]))
    (rec,) = simulate_palpations([-0.05], [-0.36], surface_z=truth.surface_z_m,
                                 kappa=truth.kappa, lam=truth.lam, beta=phantom.beta,
                                 params=params)
    data = PalpationData(t_s=rec.t_s, z_m=rec.z_m, force_N=rec.force_N,
                         surface_z_m=float(truth.surface_z_m[0]))
    lag = params.sensor.lag_samples / params.sensor.rate_hz
print(f"{data.n} samples over {data.duration_s:.1f} s")"""
        ),
        new_markdown_cell("## Table I: relative residual per model"),
        new_code_cell(
            """\
from vic_drake.reproduce.plots.offline import plot_table_i

comparison = compare_models(data, (1.5, 1.35, 1.1), lag_s=lag, sweep=not SHORT)
print(f"lag {comparison.lag_s * 1e3:.1f} ms")
print(f"Kelvin-Voigt: {comparison.kelvin_voigt.relative:.4f}")
for beta, fit in comparison.hunt_crossley.items():
    print(f"Hunt-Crossley beta={beta}: {fit.relative:.4f} (kappa {fit.kappa:.0f}, "
          f"lambda {fit.lam:.0f})")
plot_table_i(comparison)"""
        ),
        new_markdown_cell(
            "## Fig. 3: residual against palpation time\n\n"
            "Fit on the first T seconds of the palpation, evaluate on the whole "
            "palpation. The palpation starts after the approach: the first cycles, "
            "in which the probe still sinks towards its operating depth, are left "
            "out. The paper chose 5 s."
        ),
        new_code_cell(
            """\
from vic_drake.analysis.claims import residual_decay
from vic_drake.reproduce.plots.offline import plot_residual_vs_time

curve = residual_vs_palpation_time(shift(data, comparison.lag_s))
print(f"approach: {curve.approach.cycles_skipped} cycles skipped")
print(residual_decay(curve.window_s, curve.relative))
plot_residual_vs_time(curve)"""
        ),
        new_markdown_cell(
            "## Claims C1 and C2\n\n`vic_drake.analysis.claims` turns these numbers into the "
            "paper's claims with documented thresholds (the same functions the "
            "`vic-drake reproduce` report uses)."
        ),
        new_code_cell(
            """\
from vic_drake.analysis import claims

res = claims.ModelResiduals(comparison.kelvin_voigt.relative,
                            {b: f.relative for b, f in comparison.hunt_crossley.items()})
decay = (curve.window_s, curve.relative)
# The claims' two sides: the simulated palpation, or the real log's.
side = "real" if DATA is not None else "sim"
c1 = claims.claim_c1(None, res) if side == "real" else claims.claim_c1(res, None)
c2 = claims.claim_c2(None, decay) if side == "real" else claims.claim_c2(decay, None)
for claim in (c1, c2):
    passed = getattr(claim, f"pass_{side}")  # This side's verdict.
    print(claim.id, side, "PASS" if passed else "FAIL", getattr(claim, side))
    if not passed:  # The rule it missed (a short run's palpation is short).
        print("   ", claim.detail)"""
        ),
    ]


def nb_scan_controllers():
    return [
        new_markdown_cell(
            "# 2. Scans with the four controllers\n\n"
            "A UR3e with an F/T sensor and a spherical indenter scans the chest phantom "
            "along -x at 1 cm/s with the target 0.085 m high, below the surface "
            "(Sec. III-B). CS: constant stiffness 400 N/m. CF: force control at 7 N. "
            "VS-CF: stiffness from the QP tracking 7 N, penetration limited by the map. "
            "VS-VF: the force that keeps 8 mm of penetration, capped at F_min = -9 N over "
            "the ribs. All four run through the same Drake diagram "
            "(`vic_drake.experiments.MakeScanDiagram`).\n\n"
            "To stay short, the notebook runs the quick scans of `vic-drake reproduce "
            "--quick` (5 cm of scan, not the paper's 20 cm; `quick=False` below, or "
            "`diagrams/nominal_*.yaml`, gives the full scans)."
        ),
        new_code_cell(SETUP),
        new_code_cell(
            """\
from vic_drake.analysis.claims import scan_metrics
from vic_drake.experiments import run_scan
from vic_drake.reproduce import scan_limits, scan_scenario

kind = "measured" if DATA is not None else "synthetic"
controllers = ("vs-vf", "cs") if SHORT else ("cs", "cf", "vs-cf", "vs-vf")
runs = {}
for c in controllers:
    scenario = scan_scenario(c, disturbed=False, phantom_kind=kind, quick=True)
    runs[c] = run_scan(scenario, duration_s=3.0 if SHORT else None)
    print(f"{c}: {runs[c].sim_s:.1f} s simulated in {runs[c].wall_s:.1f} s")"""
        ),
        new_markdown_cell("## Fig. 6: force, stiffness, penetration and tank"),
        new_code_cell(
            """\
from vic_drake.reproduce.plots.scans import plot_fig6

plot_fig6({c: r.df for c, r in runs.items()})"""
        ),
        new_markdown_cell(
            "## Metrics\n\nForce RMSE against the reference, force range, lift-off, "
            "penetration off the ribs (see `vic_drake.analysis.claims.scan_metrics`)."
        ),
        new_code_cell(
            """\
import pandas as pd

pd.DataFrame({c: scan_metrics(r.df, limits=scan_limits(r.scenario))
              for c, r in runs.items()}).T"""
        ),
    ]


def nb_disturbance():
    return [
        new_markdown_cell(
            "# 3. The disturbance: the phantom lifted and dropped\n\n"
            "The paper lifts the dummy by hand during the scan (Fig. 7). Here the "
            "phantom's `phantom.lift` input raises it by 15 mm, then drops it below its "
            "rest, so the probe loses contact and touches again. VS-VF's energy tank "
            "and power valve keep K at K_min while contact is lost and limit its rise "
            "at re-contact; CS and CF have no such limits.\n\n"
            "To stay short, the notebook runs the quick scans of `vic-drake reproduce "
            "--quick` (a 5 cm scan with one disturbance event, not two; `quick=False` "
            "below gives the full scans)."
        ),
        new_code_cell(SETUP),
        new_code_cell(
            """\
from vic_drake.analysis.claims import scan_metrics
from vic_drake.experiments import run_scan
from vic_drake.reproduce import scan_limits, scan_scenario

kind = "measured" if DATA is not None else "synthetic"
controllers = ("vs-vf",) if SHORT else ("vs-vf", "cs", "cf")
runs = {}
for c in controllers:
    scenario = scan_scenario(c, disturbed=True, phantom_kind=kind, quick=True)
    runs[c] = run_scan(scenario, duration_s=6.0 if SHORT else None)
    print(f"{c}: {runs[c].sim_s:.1f} s simulated in {runs[c].wall_s:.1f} s")"""
        ),
        new_code_cell(
            """\
from vic_drake.reproduce.plots.scans import plot_fig7

plot_fig7({c: r.df for c, r in runs.items()})"""
        ),
        new_markdown_cell("## Tank energy and power during the disturbance"),
        new_code_cell(
            """\
df = runs["vs-vf"].df
fig, ax = plt.subplots(3, 1, sharex=True, figsize=(7, 6))
ax[0].plot(df.t_s, df.phantom_lift_m * 1e3); ax[0].set_ylabel("lift [mm]")
ax[1].plot(df.t_s, df.stiffness_z_N_per_m); ax[1].set_ylabel("K_z [N/m]")
ax[2].plot(df.t_s, df.tank_power_W); ax[2].axhline(-0.1, ls="--", c="k")
ax[2].set_ylabel("tank power [W]"); ax[2].set_xlabel("t [s]")
m = scan_metrics(df, limits=scan_limits(runs["vs-vf"].scenario))
{k: m.get(k) for k in ("n_contact_losses", "fraction_at_k_min_during_loss", "tank_min_J",
                        "tank_power_min_W", "peak_force_N")}"""
        ),
    ]


def nb_real_vs_sim():
    return [
        new_markdown_cell(
            "# 4. Real logs against simulation\n\n"
            "The paper's scan logs (when the data is there) reduced to the same metrics "
            "as the simulated scans, and one real VS-VF scan replayed in simulation on "
            "the measured map (`vic_drake.experiments.compare_real`). It needs the "
            "paper's data (without it, it says so and shows nothing)."
        ),
        new_code_cell(SETUP),
        new_code_cell(
            """\
import pandas as pd

from vic_drake.analysis.claims import scan_metrics
from vic_drake.realdata import read_bag
from vic_drake.reproduce import REAL_LIMITS, REAL_SCAN_LOGS, real_scan_frame

if DATA is None:
    print("no real data: this notebook compares the paper's logs with simulation; "
          "set VIC_DRAKE_DATA or put the data at ../shared/data")
else:
    real = {key: real_scan_frame(read_bag(DATA / "experiments" / name), controller=key[1])
            for key, name in REAL_SCAN_LOGS.items()}
    display(pd.DataFrame({f"{c} ({cond})": scan_metrics(df, limits=REAL_LIMITS)
                          for (cond, c), df in real.items()}).T)"""
        ),
        new_markdown_cell("## One real scan, simulated"),
        new_code_cell(
            """\
if DATA is not None:
    from vic_drake.experiments.compare_real import compare_real
    from vic_drake.reproduce.plots.scans import plot_comparison

    out, sim_df, real_df = compare_real(DATA / "experiments" / "test_nardi_matForce_lowR",
                                        duration_s=3.0 if SHORT else None,
                                        return_frames=True)
    # The figures are over window_s, the part of the log both runs cover.
    print({k: out[k] for k in ("controller", "window_s", "force_rmse_N", "z_rmse_mm",
                               "tank_min_J")})
    if SHORT:
        print("Short mode: 3 s simulated, so a window of a fraction of a second; "
              "the README's figures are over the whole log.")
    display(plot_comparison(sim_df, real_df, title="VS-VF: simulated vs real"))"""
        ),
    ]


def nb_online_estimation():
    return [
        new_markdown_cell(
            "# 5. Online tissue estimation\n\n"
            "The paper's future work: estimate kappa and lambda during the scan instead "
            "of in a separate palpation campaign. `vic_drake.estimation.online` holds "
            "two pure estimators on Hunt-Crossley at fixed beta, a recursive least "
            "squares with forgetting (RLS) and an extended Kalman filter (EKF); "
            "`vic_drake.systems` wraps each in a LeafSystem. Here they are replayed "
            "tick by tick over logs, then used in closed loop by VS-VF "
            "(`stiffness_source: online`)."
        ),
        new_code_cell(SETUP),
        new_markdown_cell(
            "## A palpation log\n\n"
            "Reference: the offline least-squares fit of the whole log (the paper's "
            "offline phase). Without the paper's data, a palpation simulated on the "
            "synthetic chest, whose true kappa is known."
        ),
        new_code_cell(
            """\
from vic_drake.estimation.online import OnlineEstimatorParams, run_online

if DATA is not None:
    from vic_drake.experiments.online_replay import replay_online

    replay = replay_online(DATA / "palpation" / "test_soft_2hz",
                           params=OnlineEstimatorParams(method="rls"))
    trace, kappa_ref = replay.trace, replay.kappa_ref
    print(replay.summary)
else:
    from vic_drake.experiments import CampaignParams, simulate_palpations
    from vic_drake.systems.indenter import PalpationParams
    from vic_drake.tissue import load_phantom

    phantom = load_phantom("synthetic")
    x, y = np.array([-0.05]), np.array([-0.36])
    truth = phantom.sample(x, y)
    params = CampaignParams(palpation=PalpationParams(frequency_hz=2.0,
                                                      duration_s=4.0 if SHORT else 10.0))
    (rec,) = simulate_palpations(x, y, surface_z=truth.surface_z_m, kappa=truth.kappa,
                                 lam=truth.lam, beta=phantom.beta, params=params)
    trace = run_online(rec.t_s, rec.z_m, np.gradient(rec.z_m, rec.t_s), rec.force_N,
                       float(truth.surface_z_m[0]), OnlineEstimatorParams(method="rls"))
    kappa_ref = np.full(trace.t_s.size, float(truth.kappa[0]))
fig, ax = plt.subplots(figsize=(7, 3))
ax.fill_between(trace.t_s, 0.9 * kappa_ref, 1.1 * kappa_ref, color="0.85", label="+-10 %")
ax.plot(trace.t_s, kappa_ref, "k", lw=1, label="reference")
ax.plot(trace.t_s, np.where(trace.in_contact, trace.kappa, np.nan), lw=1, label="RLS")
ax.set_xlabel("t [s]"); ax.set_ylabel("kappa"); ax.legend()"""
        ),
        new_markdown_cell(
            "## Along a scan\n\n"
            "A real VS scan (reference: the map values the controller logged, the "
            "surface it acted on) or, without the data, this package's simulated VS-VF "
            "scan on the synthetic chest (reference: the true kappa under the probe). "
            "In a scan the penetration barely changes, so lambda is not observable; "
            "kappa is, as far as the surface is right."
        ),
        new_code_cell(
            """\
from vic_drake.experiments import run_scan
from vic_drake.reproduce import scan_scenario
from vic_drake.reproduce.stages.online import replay_simulated_scan
from vic_drake.tissue import load_phantom

if DATA is not None:
    scan = replay_online(DATA / "experiments" / "test_tracking5",
                         params=OnlineEstimatorParams(method="ekf"))
    t, k_hat, k_ref, c = scan.trace.t_s, scan.trace.kappa, scan.kappa_ref, scan.trace.in_contact
    print(scan.summary)
else:
    result = run_scan(scan_scenario("vs-vf", disturbed=False, phantom_kind="synthetic", quick=True),
                      duration_s=5.0 if SHORT else None)
    tr, k_ref, summary = replay_simulated_scan(result.df, load_phantom("synthetic"),
                                               OnlineEstimatorParams(method="ekf"))
    t, k_hat, c = tr.t_s, tr.kappa, tr.in_contact
    print(summary)
fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(t, k_ref, "k", lw=1, label="reference")
ax.plot(t, np.where(c, k_hat, np.nan), lw=1, label="EKF")
ax.set_xlabel("t [s]"); ax.set_ylabel("kappa"); ax.legend()"""
        ),
        new_markdown_cell(
            "## Closed loop: true map, wrong map, online\n\n"
            "VS-VF on the synthetic chest, each run scored against the TRUE tissue "
            "(`vic_drake.experiments.online_compare`): the true map; a map with kappa "
            "x1.3 and the surface 2 mm high; and the map-free online controller, "
            "seeded with a nominal prior. A steady press cannot tell kappa from the "
            "surface (one force fits a whole curve of pairs), so these runs dither "
            "the desired penetration (0.3 mm at 3 Hz) and the estimator reads the "
            "surface from the tissue's slope under the dithered tip; the map runs "
            'get the same dither. `online_dither` is the slope fit\'s "direct" '
            'mode, `online_dither_tracker` its default "tracker" mode; both fits '
            "take the dither as their instrument, which the loop's own motion "
            "does not bias (`online_dither_ls` and `online_dither_tracker_ls`: the "
            "same by least squares).\n\n"
            "With the rig's F_min,z of -9 N the force over the ribs sits at that "
            "bound in every run, so the p99 force there is the bound's. The second "
            "table sets F_min,z to the QP's own -15 N: the ribs' force is then the "
            "controller's choice, and both modes press them with less force than "
            "the +30 % map and follow the tissue closer. Over five dither "
            "frequencies (2.9-3.1 Hz, both phantoms, both bounds) the tracker is "
            "below that map's force error in 19 of 20 runs and the direct mode in "
            "20 of 20 (docs/decisions.md, \"The dither as the slope fit's "
            'instrument, kept"). The tracker leaves out of its fit the samples '
            "where the force sits at F_min,z, and in both modes a held kappa may "
            'only fall while K_z is at K_max (docs/decisions.md, "The tracker at '
            "the controller's bounds\"). Shortened in the test suite's short mode."
        ),
        new_code_cell(
            """\
import copy

import pandas as pd

from vic_drake.experiments.online_compare import online_comparison
from vic_drake.tissue import load_phantom

RUNS = ("true_map_dither", "wrong_map_+30_dither", "online_dither",
        "online_dither_tracker")
# The whole scan (both ribs): eight scans, about a minute (73 s here).
base = scan_scenario("vs-vf", disturbed=False, phantom_kind="synthetic", quick=SHORT)
tables = {}
for bound in (-9.0, -15.0):
    scenario = copy.deepcopy(base)
    scenario.controller.reference.force_min_z_N = bound
    scores = online_comparison(scenario.validate(), phantom=load_phantom("synthetic"),
                               runs=RUNS, duration_s=4.0 if SHORT else None)
    tables[bound] = pd.DataFrame(scores).T[
        ["force_rmse_true_N", "penetration_err_mm", "kappa_rel_err_median",
         "rib_p99_force_N", "tank_min_J"]].round(3)
if SHORT:
    print("Short mode: 4 s of the scan, before the first rib: the rows cannot "
          "differ much yet; the comparison is the whole scan (run without "
          "VIC_DRAKE_SHORT).")
tables[-9.0]"""
        ),
        new_code_cell("tables[-15.0]"),
    ]


NOTEBOOKS = {
    "01_tissue_estimation.ipynb": nb_tissue_estimation,
    "02_scan_controllers.ipynb": nb_scan_controllers,
    "03_disturbance.ipynb": nb_disturbance,
    "04_real_vs_sim.ipynb": nb_real_vs_sim,
    "05_online_estimation.ipynb": nb_online_estimation,
}


def main() -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--out", default=str(HERE), help="folder to write to (default: here)"
    )
    out = Path(parser.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)
    for name, cells in NOTEBOOKS.items():
        nb = new_notebook(cells=cells())
        # Cell ids from the notebook's name and the cell's place, not random:
        # regenerating an unchanged notebook leaves the file unchanged.
        stem = Path(name).stem.split("_", 1)[0]
        for i, cell in enumerate(nb.cells):
            cell["id"] = f"nb{stem}-{i:02d}"
        nb.metadata["kernelspec"] = {
            "name": "python3",
            "display_name": "Python 3",
            "language": "python",
        }
        nbformat.write(nb, out / name)
        print(f"wrote {out / name}")


if __name__ == "__main__":
    main()
