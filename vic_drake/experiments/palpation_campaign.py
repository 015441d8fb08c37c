"""Palpation campaign: simulate palpating a phantom on a grid and fit every point.

The paper's offline phase (Sec. II-A, IV-A): at points 1 cm apart the robot
descends until it touches the body, then palpates sinusoidally (15 mm below
the surface, 8 mm amplitude, 2.5 Hz, 5 s) while the F/T sensor logs the
force; a Hunt-Crossley fit at fixed beta gives kappa and lambda per point.
Here the palpations run on the indenter bank
(:func:`~vic_drake.experiments.palpation_sim.simulate_palpations`: all points
of a batch in ONE diagram; with more than one worker, or a scheduler, the
batches run on Dask: :mod:`vic_drake.experiments.dask_cluster`), then each
point is reduced by :func:`~vic_drake.experiments.palpation_fit.fit_point`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign_params import CampaignParams
from vic_drake.experiments.palpation_fit import campaign_lag, fit_point
from vic_drake.experiments.palpation_sim import SimulatedPalpation, simulate_palpations
from vic_drake.tissue import DEFAULT_RELAXATION, Phantom, RelaxationParams


def grid_points(region_m, spacing_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Points of a regular grid over a region, starting at its low corner.

    Returns:
        (x, y): flattened arrays, x-major (all y of the first x first).
    """
    x_min, x_max, y_min, y_max = region_m
    if not (np.isfinite(spacing_m) and spacing_m > 0):
        raise VicDrakeError(f"spacing must be > 0, got {spacing_m!r}")
    nx = int(np.floor((x_max - x_min) / spacing_m + 1e-9)) + 1
    ny = int(np.floor((y_max - y_min) / spacing_m + 1e-9)) + 1
    X, Y = np.meshgrid(
        x_min + spacing_m * np.arange(nx),
        y_min + spacing_m * np.arange(ny),
        indexing="ij",
    )
    return X.ravel(), Y.ravel()


def _simulate_batch(args):
    x, y, s, k, lam, beta, params, seed, relaxation, ids = args
    start = time.perf_counter()
    records = simulate_palpations(
        x,
        y,
        surface_z=s,
        kappa=k,
        lam=lam,
        beta=beta,
        params=params,
        seed=seed,
        relaxation=relaxation,
        ids=ids,
    )
    return records, time.perf_counter() - start


def _simulate_batch_in_child(args):
    """:func:`_simulate_batch` in a process of its own, what a Dask worker
    runs (:func:`~vic_drake.experiments.child_process.run_in_child`): the
    worker stays free, so a cluster stopped by Ctrl-C closes without a busy
    worker's complaint, and it does not keep each batch's Diagram."""
    from vic_drake.experiments.child_process import run_in_child

    return run_in_child(_simulate_batch, args)


def _fit_batch(args):
    records, beta, lag_s, params = args
    return [fit_point(r, beta=beta, lag_s=lag_s, params=params) for r in records]


@dataclass
class CampaignResult:
    """A fitted palpation campaign.

    Attributes:
        points: DataFrame, one row per point: x_m, y_m, surface_z_m,
            kappa_N_per_m_beta, lambda_N_s_per_m_beta1, rms_N, relative, ok,
            and the phantom's truth surface_true_z_m, kappa_true_N_per_m_beta,
            lambda_true_N_s_per_m_beta1.
        beta: exponent of the fits.
        lag_s: sensor lag used.
        region_m: the palpated region.
        simulate_s, fit_s: wall times, s (simulate_s sums worker times).
        wall_s: total wall time, s.
        records: the simulated logs (kept if requested).
    """

    points: pd.DataFrame
    beta: float
    lag_s: float
    region_m: tuple[float, float, float, float]
    simulate_s: float
    fit_s: float
    wall_s: float
    records: list[SimulatedPalpation] | None = None

    @property
    def ok(self) -> pd.DataFrame:
        return self.points[self.points["ok"]]


def _simulate_on_cluster(make_jobs, workers, scheduler, say) -> list:
    """The batches of ``make_jobs(cluster workers)`` simulated on Dask (a
    local cluster of ``workers`` processes, or the cluster at ``scheduler``),
    in order (:func:`~vic_drake.experiments.dask_cluster.map_on_cluster`)."""
    from vic_drake.experiments.dask_cluster import map_on_cluster

    n_jobs = []

    def jobs(n_workers: int) -> list:
        made = make_jobs(n_workers)
        n_jobs.append(len(made))
        return made

    return map_on_cluster(
        _simulate_batch_in_child,
        jobs,
        workers,
        scheduler,
        name="palpation-batch",
        describe=lambda k: f"palpation batch {k + 1} of {n_jobs[0]}",
        on_done=lambda k, out, done: say(
            f"batch {done} of {n_jobs[0]} done ({len(out[0])} points)"
        ),
    )


def run_campaign(
    phantom: Phantom,
    params: CampaignParams | None = None,
    *,
    keep_records: bool = False,
    progress=None,
    relaxation: RelaxationParams | None = DEFAULT_RELAXATION,
    scheduler: str | None = None,
) -> CampaignResult:
    """Palpates a phantom on a grid and fits every point.

    Args:
        phantom: any :class:`vic_drake.tissue.Phantom` (its beta is used;
            its kappa is the tissue's instantaneous modulus).
        params: campaign parameters.
        relaxation: the simulated tissue's relaxation (None: plain
            Hunt-Crossley); see :func:`simulate_palpations`.
        keep_records: keep the simulated logs in the result.
        progress: optional callable(str) for progress lines.
        scheduler: address of an existing Dask scheduler to simulate the
            batches on (``params.workers`` is then not read). Without it,
            ``params.workers`` > 1 starts a local Dask cluster of that many
            worker processes, and 1 simulates in this process.

    Returns:
        A :class:`CampaignResult`.
    """
    params = params or CampaignParams()
    say = progress or (lambda message: None)
    start = time.perf_counter()
    region = params.region_m or tuple(float(v) for v in phantom.bounds)
    x, y = grid_points(region, params.spacing_m)
    truth = phantom.sample(x, y)
    beta = float(phantom.beta)
    n = x.size
    workers = int(params.workers)

    def make_jobs(n_workers: int) -> list:
        n_batches = max(int(np.ceil(n / params.batch_size)), min(n_workers, n))
        chunks = np.array_split(np.arange(n), n_batches)
        return [
            (
                x[c],
                y[c],
                truth.surface_z_m[c],
                truth.kappa[c],
                truth.lam[c],
                beta,
                params,
                params.seed,
                relaxation,
                c,  # The points' ids: their noise does not follow the split.
            )
            for c in chunks
        ]

    t0 = time.perf_counter()
    if scheduler is None and workers == 1:
        jobs = make_jobs(1)
        say(f"palpating {n} points in {len(jobs)} batch(es) in this process")
        outs = [_simulate_batch(job) for job in jobs]
    else:
        where = (
            f"the Dask cluster at {scheduler}"
            if scheduler
            else (f"{workers} local Dask worker(s)")
        )
        say(f"palpating {n} points on {where}")
        outs = _simulate_on_cluster(make_jobs, workers, scheduler, say)
    records = [r for batch, _ in outs for r in batch]
    simulate_s = time.perf_counter() - t0
    say(f"simulated {n} palpations in {simulate_s:.1f} s")
    t1 = time.perf_counter()
    lag_s = campaign_lag(records, beta=beta, params=params)
    say(f"sensor lag {lag_s * 1e3:.1f} ms; fitting {n} points")
    fits = _fit_batch((records, beta, lag_s, params))
    fit_s = time.perf_counter() - t1
    ok = np.array([f.ok for f in fits])
    if not ok.any():
        raise VicDrakeError(
            f"no palpation point could be fitted ({fits[0].message}); check the phantom "
            "and the palpation parameters"
        )
    points = pd.DataFrame(
        {
            "x_m": x,
            "y_m": y,
            "surface_z_m": [f.surface_z_m for f in fits],
            "kappa_N_per_m_beta": [f.kappa for f in fits],
            "lambda_N_s_per_m_beta1": [f.lam for f in fits],
            "rms_N": [f.rms_N for f in fits],
            "relative": [f.relative for f in fits],
            "n_samples": [f.n_samples for f in fits],
            "noise_N": [f.noise_N for f in fits],
            "ok": ok,
            "message": [f.message for f in fits],
            "surface_true_z_m": truth.surface_z_m,
            "kappa_true_N_per_m_beta": truth.kappa,
            "lambda_true_N_s_per_m_beta1": truth.lam,
        }
    )
    say(f"fitted {int(ok.sum())}/{n} points in {fit_s:.1f} s")
    return CampaignResult(
        points=points,
        beta=beta,
        lag_s=lag_s,
        region_m=region,
        simulate_s=simulate_s,
        fit_s=fit_s,
        wall_s=time.perf_counter() - start,
        records=records if keep_records else None,
    )


__all__ = ["CampaignResult", "grid_points", "run_campaign"]
