"""Stage ``offline_sim``: the offline fits on palpations simulated on the phantom."""

from __future__ import annotations

import numpy as np
import pandas as pd

from vic_drake.reproduce.context import RunContext, _write_log
from vic_drake.reproduce.stages.offline_fits import offline_fits
from vic_drake.tissue import load_phantom

#: Simulated palpations: (frequency Hz) per log, and where (x, y) on the phantom.
SIM_PALPATION_FREQUENCIES_HZ = (1.0, 2.0, 2.5)
SIM_PALPATION_POINT_M = (-0.05, -0.36)


def stage_offline_sim(ctx: RunContext) -> dict:
    """The same fits on palpations simulated on the phantom (Drake indenter bank).

    The simulated tissue is Hunt-Crossley with the phantom's beta (1.35), so
    C1 in simulation checks that the estimation pipeline (lag, noise, indenter
    mass, contact selection) recovers the model, not that tissue is HC.
    """
    # Function-local: the campaign and the indenter pull in pydrake (heavy).
    from vic_drake.estimation.palpation import PalpationData
    from vic_drake.experiments import CampaignParams, simulate_palpations
    from vic_drake.systems.indenter import PalpationParams

    phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
    duration = 10.0 if ctx.options.quick else 20.0
    freqs = (2.5,) if ctx.options.quick else SIM_PALPATION_FREQUENCIES_HZ
    x, y = (np.array([v]) for v in SIM_PALPATION_POINT_M)
    truth = phantom.sample(x, y)
    logs = {}
    for k, f in enumerate(freqs):
        params = CampaignParams(
            palpation=PalpationParams(frequency_hz=f, duration_s=duration), seed=k
        )
        ctx.progress(f"  simulating a {duration:g} s palpation at {f:g} Hz")
        (rec,) = simulate_palpations(
            x,
            y,
            surface_z=truth.surface_z_m,
            kappa=truth.kappa,
            lam=truth.lam,
            beta=phantom.beta,
            params=params,
            seed=k,
        )
        lag = params.sensor.lag_samples / params.sensor.rate_hz
        name = f"palpation_sim_{f:g}hz"
        _write_log(
            ctx,
            name,
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
            },
        )
        data = PalpationData(
            t_s=rec.t_s,
            z_m=rec.z_m,
            force_N=rec.force_N,
            surface_z_m=float(truth.surface_z_m[0]),
            z_target_m=rec.z_target_m,
        )
        logs[f"sim_{f:g}hz"] = (data, lag)
    out = offline_fits(ctx, logs, "sim")
    out["truth"] = {"kappa": float(truth.kappa[0]), "lam": float(truth.lam[0])}
    return out
