"""Stage ``offline_sim``: the offline fits on palpations simulated on the phantom."""

from __future__ import annotations

import numpy as np
import pandas as pd

from vic_drake.analysis.claims.offline import c2_decay
from vic_drake.paper import BEST_BETA
from vic_drake.reproduce.context import RunContext, _write_log
from vic_drake.reproduce.stages.offline_fits import offline_fits
from vic_drake.tissue import DEFAULT_RELAXATION, load_phantom

#: Simulated palpations: (frequency Hz) per log, and where (x, y) on the phantom.
SIM_PALPATION_FREQUENCIES_HZ = (1.0, 2.0, 2.5)
SIM_PALPATION_POINT_M = (-0.05, -0.36)


def _simulate(ctx, phantom, truth, xy, *, freqs, duration, relaxation, tag) -> tuple:
    """Simulated palpations at each frequency -> ({name: (PalpationData,
    lag_s)}, {frequency: its bag folder}: the relaxing tissue's only)."""
    # Function-local: the campaign and the indenter pull in pydrake (heavy).
    from vic_drake.estimation.palpation import PalpationData
    from vic_drake.experiments import CampaignParams, simulate_palpations
    from vic_drake.experiments.rig_log import write_palpation_bag
    from vic_drake.systems.indenter import PalpationParams

    law = "hc" if relaxation is None else "relaxing"
    x, y = xy
    logs, bags = {}, {}
    for k, f in enumerate(freqs):
        params = CampaignParams(
            palpation=PalpationParams(frequency_hz=f, duration_s=duration), seed=k
        )
        ctx.progress(f"  simulating a {duration:g} s palpation at {f:g} Hz ({law})")
        (rec,) = simulate_palpations(
            x,
            y,
            surface_z=truth.surface_z_m,
            kappa=truth.kappa,
            lam=truth.lam,
            beta=phantom.beta,
            params=params,
            seed=k,
            relaxation=relaxation,
        )
        lag = params.sensor.lag_samples / params.sensor.rate_hz
        _write_log(
            ctx,
            f"palpation_sim{tag}_{f:g}hz",
            pd.DataFrame(
                {
                    "t_s": rec.t_s,
                    "z_m": rec.z_m,
                    "z_target_m": rec.z_target_m,
                    "force_z_N": rec.force_N,  # Positive = the body pushes the probe up.
                }
            ),
            {
                "campaign_params": params,
                "point_xy_m": [float(x[0]), float(y[0])],
                "phantom": ctx.phantom_kind,
                "seed": k,
                "tissue_law": law,
                "relaxation": relaxation,
            },
        )
        if tag == "":  # The relaxing tissue's palpations also as the rig's bags.
            bags[f] = write_palpation_bag(
                rec,
                ctx.out_dir / "logs" / f"palpation_sim_{f:g}hz_bag",
                surface_z_m=float(truth.surface_z_m[0]),
            )
        data = PalpationData(
            t_s=rec.t_s,
            z_m=rec.z_m,
            force_N=rec.force_N,
            surface_z_m=float(truth.surface_z_m[0]),
            z_target_m=rec.z_target_m,
        )
        logs[f"sim_{f:g}hz"] = (data, lag)
    return logs, bags


def _errors(fits: dict, kappa: float, kappa_relaxed: float, lam: float) -> dict:
    """Relative errors of the HC fits (beta = 1.35) against the truth."""
    return {
        name: {
            "kappa": fit.kappa,
            "lam": fit.lam,
            "kappa_rel_error_vs_instantaneous": fit.kappa / kappa - 1.0,
            "kappa_rel_error_vs_relaxed": fit.kappa / kappa_relaxed - 1.0,
            "lam_rel_error": fit.lam / lam - 1.0,
        }
        for name, fit in fits.items()
    }


def stage_offline_sim(ctx: RunContext) -> dict:
    """The same fits on palpations simulated on the phantom (Drake indenter bank).

    The simulated tissue is the relaxing Hunt-Crossley law
    (:data:`vic_drake.tissue.DEFAULT_RELAXATION`, identified on the real
    palpations, unless the options give another; the phantom's kappa is its
    instantaneous modulus) with the phantom's beta (1.35); the estimator
    fits plain HC at that beta. A control run on plain-HC tissue
    (``control_hc``) shows what the relaxation changes: on its own model the
    estimator fits a short palpation as well as a long one, so C2's fall
    needs the relaxation.
    Besides the fits of :func:`offline_fits`, the result holds the truth
    (instantaneous and relaxed kappa, lambda), the fits' errors against it,
    and C2's metric on both tissues.
    """
    from vic_drake.estimation.palpation import (
        fit_hunt_crossley,
        residual_vs_palpation_time,
        shift,
    )

    phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
    duration = 10.0 if ctx.options.quick else 20.0
    freqs = (2.5,) if ctx.options.quick else SIM_PALPATION_FREQUENCIES_HZ
    xy = tuple(np.array([v]) for v in SIM_PALPATION_POINT_M)
    truth = phantom.sample(*xy)
    kappa, lam = float(truth.kappa[0]), float(truth.lam[0])
    relaxation = ctx.options.relaxation or DEFAULT_RELAXATION
    kappa_relaxed = relaxation.long_term_fraction * kappa
    run = dict(freqs=freqs, duration=duration)
    logs, bags = _simulate(
        ctx, phantom, truth, xy, relaxation=relaxation, tag="", **run
    )
    out = offline_fits(ctx, logs, "sim")
    out["palpation_bags"] = bags  # Replayed by the online stage.
    out["truth"] = {
        "kappa": kappa,
        "kappa_relaxed": kappa_relaxed,
        "lam": lam,
        "tissue_law": "relaxing",
        "relaxation": relaxation.as_dict(),
    }
    fits = {n: c.hunt_crossley[BEST_BETA] for n, c in out["comparisons"].items()}
    out["estimation_error"] = _errors(fits, kappa, kappa_relaxed, lam)
    c2, c2_pass = c2_decay(out["decay"])
    out["c2_relaxing"] = {"value": c2, "pass": c2_pass}

    ctx.progress("  control: the same palpations on plain Hunt-Crossley tissue")
    control, _ = _simulate(ctx, phantom, truth, xy, relaxation=None, tag="_hc", **run)
    decay, fits = {}, {}
    for name, (data, lag) in control.items():
        aligned = shift(data, lag)
        fits[name] = fit_hunt_crossley(aligned, BEST_BETA)
        curve = residual_vs_palpation_time(aligned, beta=BEST_BETA)
        decay[name] = (curve.window_s, curve.relative)
    c2, c2_pass = c2_decay(decay)
    out["control_hc"] = {
        "tissue_law": "hc",
        "decay": decay,
        "c2": c2,
        "c2_pass": c2_pass,
        "estimation_error": _errors(fits, kappa, kappa, lam),
    }
    return out
