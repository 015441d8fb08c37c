"""Simulated palpations: n points palpated at once in one indenter-bank diagram.

:func:`simulate_palpations` runs the real rig's procedure (descend until the
force rises, then palpate sinusoidally below that height) on the indenter
bank of :mod:`vic_drake.experiments.indenter_bank` and returns each point's
logs at the sensor rate as a :class:`SimulatedPalpation`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.systems.analysis import Simulator

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign_params import CampaignParams
from vic_drake.experiments.indenter_bank import MakeIndenterDiagram
from vic_drake.tissue import DEFAULT_RELAXATION, RelaxationParams


@dataclass(frozen=True)
class SimulatedPalpation:
    """The logs of one simulated palpation, at the sensor rate.

    Attributes:
        x_m, y_m: where.
        t_s: (n,) times from the start of the approach, s.
        z_m: (n,) tip height, m. z_target_m: (n,) servo target, m.
        force_N: (n,) measured force (lagged, noisy, positive up), N.
        t_contact_s: when the measured force crossed the contact threshold
            (NaN if never). z_contact_m: the tip height then.
    """

    x_m: float
    y_m: float
    t_s: np.ndarray
    z_m: np.ndarray
    z_target_m: np.ndarray
    force_N: np.ndarray
    t_contact_s: float
    z_contact_m: float


def simulate_palpations(
    x,
    y,
    *,
    surface_z,
    kappa,
    lam,
    beta: float,
    params: CampaignParams,
    seed: int = 0,
    relaxation: RelaxationParams | None = DEFAULT_RELAXATION,
    ids=None,
) -> list[SimulatedPalpation]:
    """Palpates n points at once in one indenter-bank diagram.

    Args:
        x, y: (n,) point positions (only recorded).
        surface_z, kappa, lam: (n,) true tissue under each point (kappa:
            the instantaneous modulus of a relaxing tissue).
        beta: Hunt-Crossley exponent.
        params: the campaign (palpation, indenter, sensor).
        seed: seed of the sensor noise.
        ids: (n,) integer ids of the points (default 0..n-1): point i's
            sensor noise is drawn from (seed, ids[i]) alone, so a point
            palpated with other points, or in another batch, reads the same
            noise.
        relaxation: the tissue's relaxation (:mod:`vic_drake.tissue.relaxation`,
            any number of branches); None: plain Hunt-Crossley tissue (the
            one-branch element with g = 0).
    """
    x, y, surface_z, kappa, lam = (
        np.atleast_1d(np.asarray(a, float)) for a in (x, y, surface_z, kappa, lam)
    )
    n = x.size
    sizes = {a.size for a in (x, y, surface_z, kappa, lam)}
    if len(sizes) != 1 or n == 0:
        raise VicDrakeError(
            "simulate_palpations: x, y, surface_z, kappa, lam must have one common "
            f"non-zero size; got {[a.size for a in (x, y, surface_z, kappa, lam)]}"
        )
    if not np.all(np.isfinite(np.concatenate([surface_z, kappa, lam]))):
        raise VicDrakeError("simulate_palpations: surface_z, kappa, lam must be finite")
    pal = params.palpation
    bank = MakeIndenterDiagram(
        n,
        beta=beta,
        indenter=params.indenter,
        sensor=params.sensor,
        palpation=pal,
        relaxation=relaxation or DEFAULT_RELAXATION,
    )
    context = bank.diagram.CreateDefaultContext()
    bank.set_points(
        context,
        surface_z=surface_z,
        kappa=kappa,
        lam=lam,
        start_z=surface_z + pal.start_clearance_m,
        seed=seed,
        ids=_point_ids(ids, n),
    )
    bank.tissue.set_relaxation(
        bank.tissue.GetMyMutableContextFromRoot(context), relaxation
    )
    simulator = Simulator(bank.diagram, context)
    # Run the longest allowed approach, then until the last point to touch
    # has palpated for the full duration.
    simulator.AdvanceTo(pal.max_approach_s)
    contact = bank.contact_logger.FindLog(context).data()[:, -1].reshape(3, n)
    t_c = np.where(contact[0] > 0.5, contact[2], np.nan)
    t_end = (np.nanmax(t_c) if np.any(np.isfinite(t_c)) else 0.0) + pal.duration_s
    period = params.sensor.period_s
    simulator.AdvanceTo(max(t_end + 2 * period, pal.max_approach_s))

    t = bank.state_logger.FindLog(context).sample_times()
    q = bank.state_logger.FindLog(context).data()[:n]
    force = bank.force_logger.FindLog(context).data()
    z_d = bank.target_logger.FindLog(context).data()[:n]
    contact = bank.contact_logger.FindLog(context).data()[:, -1].reshape(3, n)
    records = []
    for i in range(n):
        touched = contact[0, i] > 0.5
        t_ci = contact[2, i] if touched else np.nan
        end = np.searchsorted(
            t, (t_ci if touched else 0.0) + pal.duration_s, side="right"
        )
        records.append(
            SimulatedPalpation(
                x_m=float(x[i]),
                y_m=float(y[i]),
                t_s=t[:end].copy(),
                z_m=q[i, :end].copy(),
                z_target_m=z_d[i, :end].copy(),
                force_N=force[i, :end].copy(),
                t_contact_s=float(t_ci),
                z_contact_m=float(contact[1, i]) if touched else np.nan,
            )
        )
    return records


def _point_ids(ids, n: int) -> np.ndarray:
    if ids is None:
        return np.arange(n)
    out = np.atleast_1d(np.asarray(ids))
    if out.shape != (n,) or not np.issubdtype(out.dtype, np.integer) or np.any(out < 0):
        raise VicDrakeError(
            "simulate_palpations: ids must be one integer >= 0 per point "
            f"({n} points); got {ids!r}"
        )
    return out


__all__ = ["SimulatedPalpation", "simulate_palpations"]
