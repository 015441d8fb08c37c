"""Reducing one simulated palpation: tare, lag, contact point and Hunt-Crossley fit.

How each point is reduced (:func:`fit_point`):

1. Tare and noise: ``free_air_s`` of the log once the sensor's delay line
   has filled (the probe starts ``start_clearance_m`` above the skin) give
   the force offset, subtracted, and the noise std.
2. Lag: the force is advanced by the sensor lag, the rig's calibrated
   value by default (``CampaignParams.lag_s``; optionally estimated, see
   ``CampaignParams.estimate_lag``).
3. Contact point = surface estimate, "where the force first rises": the
   first sample of the approach at which the aligned force exceeds
   ``rise_sigmas`` noise stds (and ``rise_min_N``) and stays above for
   ``rise_hold_samples``; the tip is already a little inside the tissue
   there, so the estimate is corrected by the Hunt-Crossley penetration that
   produces that force at that penetration rate,
   ``s = z_rise + (F_rise / (kappa + lambda eps_dot_rise))^(1/beta)``, with
   kappa, lambda from the fit, iterated ``surface_iterations`` times.
4. Fit: Hunt-Crossley at the phantom's beta on the 5 s palpation segment
   with the surface estimate of step 3.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation import (
    PalpationData,
    estimate_lag,
    fit_hunt_crossley,
    shift,
)
from vic_drake.experiments.campaign_params import CampaignParams
from vic_drake.experiments.palpation_sim import SimulatedPalpation


@dataclass(frozen=True)
class PointFit:
    """The reduction of one palpation (see the module docstring).

    Attributes:
        surface_z_m: surface estimate (contact point), m.
        kappa, lam: Hunt-Crossley fit at beta. rms_N, relative: its residual.
        n_samples: samples fitted. tare_N, noise_N: free-air offset and std.
        z_rise_m: tip height where the force first rose, m.
        ok: False when the point could not be fitted (values NaN).
        message: why not.
    """

    surface_z_m: float
    kappa: float
    lam: float
    rms_N: float
    relative: float
    n_samples: int
    tare_N: float
    noise_N: float
    z_rise_m: float
    ok: bool = True
    message: str = ""


def _failed(message: str, tare=np.nan, noise=np.nan) -> PointFit:
    nan = float("nan")
    return PointFit(
        nan, nan, nan, nan, nan, 0, float(tare), float(noise), nan, False, message
    )


def fit_point(
    record: SimulatedPalpation, *, beta: float, lag_s: float, params: CampaignParams
) -> PointFit:
    """Tare, align, find the contact point and fit Hunt-Crossley (module docstring)."""
    if not np.isfinite(record.t_contact_s):
        return _failed("no contact: the force never crossed the contact threshold")
    t, z, force = record.t_s, record.z_m, record.force_N
    # Free air: after the sensor's delay line has filled, before any contact.
    free = (t >= t[0] + lag_s) & (t < t[0] + lag_s + params.free_air_s)
    if free.sum() < 5:
        return _failed("fewer than 5 free-air samples")
    tare = float(np.mean(force[free]))
    noise = float(np.std(force[free]))
    data = PalpationData(
        t_s=t,
        z_m=z,
        force_N=force - tare,
        surface_z_m=0.0,
        z_target_m=record.z_target_m,
    )
    aligned = shift(data, lag_s)
    f = aligned.force_N
    threshold = max(params.rise_sigmas * noise, params.rise_min_N)
    above = f > threshold
    hold = params.rise_hold_samples
    run = np.convolve(above.astype(int), np.ones(hold, int), mode="valid") == hold
    if not run.any():
        return _failed("the force never rose above the noise", tare, noise)
    i_rise = int(np.argmax(run))
    z_rise = float(aligned.z_m[i_rise])
    z_dot_rise = float(np.gradient(aligned.z_m, aligned.t_s)[max(i_rise, 1)])
    f_rise = float(f[i_rise])
    palpating = aligned.t_s >= record.t_contact_s
    segment = aligned.select(palpating)
    surface = z_rise

    def fit_with_surface(surface_z_m: float):
        pdata = PalpationData(
            t_s=segment.t_s,
            z_m=segment.z_m,
            force_N=segment.force_N,
            surface_z_m=surface_z_m,
            z_target_m=segment.z_target_m,
        )
        return fit_hunt_crossley(
            pdata, beta, indenter_mass_kg=params.indenter.indenter_mass_kg
        )

    fit = None
    try:
        for _ in range(params.surface_iterations):
            fit = fit_with_surface(surface)
            stiffness = fit.kappa + fit.lam * max(-z_dot_rise, 0.0)
            if not stiffness > 0:
                break
            surface = z_rise + (f_rise / stiffness) ** (1.0 / beta)
        fit = fit_with_surface(surface)
    except VicDrakeError as exc:
        return _failed(f"fit failed: {exc}", tare, noise)
    return PointFit(
        surface_z_m=float(surface),
        kappa=fit.kappa,
        lam=fit.lam,
        rms_N=fit.rms_N,
        relative=fit.relative,
        n_samples=fit.n_samples,
        tare_N=tare,
        noise_N=noise,
        z_rise_m=z_rise,
    )


def campaign_lag(records, *, beta: float, params: CampaignParams) -> float:
    """The sensor lag, s (see CampaignParams.lag_s and estimate_lag)."""
    if not params.estimate_lag:
        if params.lag_s is not None:
            return float(params.lag_s)
        return params.sensor.lag_samples * params.sensor.period_s
    lags = []
    for record in records:
        if len(lags) >= params.lag_calibration_points:
            break
        if not np.isfinite(record.t_contact_s):
            continue
        segment = record.t_s >= record.t_contact_s
        free = record.t_s < record.t_s[0] + params.free_air_s  # Lag unknown yet.
        tare = float(np.mean(record.force_N[free])) if free.any() else 0.0
        data = PalpationData(
            t_s=record.t_s[segment],
            z_m=record.z_m[segment],
            force_N=record.force_N[segment] - tare,
            surface_z_m=record.z_contact_m,
        )
        try:
            lags.append(
                estimate_lag(
                    data, beta=beta, indenter_mass_kg=params.indenter.indenter_mass_kg
                )
            )
        except VicDrakeError:
            continue
    if not lags:
        raise VicDrakeError(
            "cannot estimate the sensor lag: no palpation reached contact"
        )
    return float(np.median(lags))


__all__ = ["PointFit", "campaign_lag", "fit_point"]
