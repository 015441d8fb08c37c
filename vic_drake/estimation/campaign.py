"""Palpation campaign: simulate palpating a phantom on a grid and fit every point.

The paper's offline phase (Sec. II-A, IV-A): at points 1 cm apart the robot
descends until it touches the body, then palpates sinusoidally (15 mm below
the surface, 8 mm amplitude, 2.5 Hz, 5 s) while the F/T sensor logs the
force; a Hunt-Crossley fit at fixed beta gives kappa and lambda per point.
Here the palpations run on the indenter bank of
:mod:`vic_drake.systems.indenter` (all points of a batch in ONE diagram,
batches split over worker processes), then each point is fitted with
:func:`vic_drake.estimation.palpation.fit_hunt_crossley`.

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

import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation import (
    PalpationData,
    estimate_lag,
    fit_hunt_crossley,
    shift,
)
from vic_drake.systems.indenter import (
    IndenterParams,
    MakeIndenterDiagram,
    PalpationParams,
    SensorParams,
)
from vic_drake.tissue import Phantom


@dataclass(frozen=True)
class CampaignParams:
    """Everything that defines a palpation campaign (SI units).

    Attributes:
        spacing_m: grid spacing of the palpation points (paper: 1 cm).
        region_m: (x_min, x_max, y_min, y_max) to palpate; None = the
            phantom's bounds. Points start at (x_min, y_min).
        palpation, indenter, sensor: the procedure, the indenter and its
            servo, the F/T sensor model.
        lag_s: sensor lag used to align force and position, s; None uses the
            rig's calibration, ``sensor.lag_samples / sensor.rate_hz`` (the
            real controller's 28 samples).
        estimate_lag: estimate the lag from the logs instead (median of
            :func:`~vic_drake.estimation.palpation.estimate_lag` over
            ``lag_calibration_points`` points). At a single palpation
            frequency a lag and a viscous term look alike: on simulated
            logs with a true lag of 56 ms it returned 45 ms (4 points on the
            synthetic chest), which left lambda 12-17 % low and kappa 1-4 %
            high; hence off by default.
        lag_calibration_points: points used to estimate the lag (median).
        free_air_s: initial span used for the tare and the noise std.
        rise_sigmas, rise_min_N, rise_hold_samples: force-rise detection.
        surface_iterations: fixed-point iterations of the surface correction
            (each one refits; on 36 measured-map points 1, 2 and 3 iterations
            gave kappa 1.05 / 1.16 / 1.17 % and surface 0.063 / 0.071 /
            0.072 mm RMS error, so one).
        batch_size: indenters per simulated diagram. The cost of a step is
            mostly per-step overhead, so bigger banks are cheaper per point
            (231 points: one bank of 231 took 16.6 s, banks of 16 took 58 s
            on a loaded 2-core machine; one single-indenter diagram re-run
            per point took 3.9 s per point against 0.1 s in a bank of 40).
        workers: worker processes for the simulation (1: in-process). With
            more, batches run in "spawn" processes, so a calling script needs
            the ``if __name__ == "__main__":`` guard. On 2 cores the gain is
            small (the whole 231-point measured campaign takes about 20 s
            in-process), hence 1 by default.
        seed: seed of the sensor noise (batch k uses seed + k).
    """

    spacing_m: float = 0.01
    region_m: tuple[float, float, float, float] | None = None
    palpation: PalpationParams = field(default_factory=PalpationParams)
    indenter: IndenterParams = field(default_factory=IndenterParams)
    sensor: SensorParams = field(default_factory=SensorParams)
    lag_s: float | None = None
    estimate_lag: bool = False
    lag_calibration_points: int = 5
    free_air_s: float = 0.08
    rise_sigmas: float = 4.0
    rise_min_N: float = 0.05
    rise_hold_samples: int = 5
    surface_iterations: int = 1
    batch_size: int = 256
    workers: int = 1
    seed: int = 0

    def __post_init__(self):
        if not (np.isfinite(self.spacing_m) and self.spacing_m > 0):
            raise VicDrakeError(
                f"CampaignParams.spacing_m must be > 0, got {self.spacing_m!r}"
            )
        if self.region_m is not None:
            r = tuple(float(v) for v in self.region_m)
            if len(r) != 4 or not all(np.isfinite(r)) or r[1] < r[0] or r[3] < r[2]:
                raise VicDrakeError(
                    "CampaignParams.region_m must be (x_min, x_max, y_min, y_max) with "
                    f"x_min <= x_max and y_min <= y_max, got {self.region_m!r}"
                )
            object.__setattr__(self, "region_m", r)
        if self.lag_s is not None and not (np.isfinite(self.lag_s) and self.lag_s >= 0):
            raise VicDrakeError(
                f"CampaignParams.lag_s must be >= 0 or None, got {self.lag_s!r}"
            )
        for name in (
            "lag_calibration_points",
            "batch_size",
            "rise_hold_samples",
            "surface_iterations",
        ):
            value = getattr(self, name)
            if int(value) != value or value < 1:
                raise VicDrakeError(
                    f"CampaignParams.{name} must be an integer >= 1, got {value!r}"
                )
        if int(self.workers) != self.workers or self.workers < 1:
            raise VicDrakeError(
                f"CampaignParams.workers must be an integer >= 1, got {self.workers!r}"
            )
        for name in ("free_air_s", "rise_sigmas"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise VicDrakeError(f"CampaignParams.{name} must be > 0, got {value!r}")
        if not (np.isfinite(self.rise_min_N) and self.rise_min_N >= 0):
            raise VicDrakeError(
                f"CampaignParams.rise_min_N must be >= 0, got {self.rise_min_N!r}"
            )


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
    x, y, *, surface_z, kappa, lam, beta: float, params: CampaignParams, seed: int = 0
) -> list[SimulatedPalpation]:
    """Palpates n points at once in one indenter-bank diagram.

    Args:
        x, y: (n,) point positions (only recorded).
        surface_z, kappa, lam: (n,) true tissue under each point.
        beta: Hunt-Crossley exponent.
        params: the campaign (palpation, indenter, sensor).
        seed: seed of the sensor noise.
    """
    from pydrake.systems.analysis import Simulator

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
        n, beta=beta, indenter=params.indenter, sensor=params.sensor, palpation=pal
    )
    context = bank.diagram.CreateDefaultContext()
    bank.set_points(
        context,
        surface_z=surface_z,
        kappa=kappa,
        lam=lam,
        start_z=surface_z + pal.start_clearance_m,
        seed=seed,
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


def _simulate_batch(args):
    x, y, s, k, lam, beta, params, seed = args
    start = time.perf_counter()
    records = simulate_palpations(
        x, y, surface_z=s, kappa=k, lam=lam, beta=beta, params=params, seed=seed
    )
    return records, time.perf_counter() - start


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


def _pool(workers: int):
    import multiprocessing

    return ProcessPoolExecutor(
        max_workers=workers, mp_context=multiprocessing.get_context("spawn")
    )


def run_campaign(
    phantom: Phantom,
    params: CampaignParams | None = None,
    *,
    keep_records: bool = False,
    progress=None,
) -> CampaignResult:
    """Palpates a phantom on a grid and fits every point.

    Args:
        phantom: any :class:`vic_drake.tissue.Phantom` (its beta is used).
        params: campaign parameters.
        keep_records: keep the simulated logs in the result.
        progress: optional callable(str) for progress lines.

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
    n_batches = max(int(np.ceil(n / params.batch_size)), min(workers, n))
    chunks = np.array_split(np.arange(n), n_batches)
    jobs = [
        (
            x[c],
            y[c],
            truth.surface_z_m[c],
            truth.kappa[c],
            truth.lam[c],
            beta,
            params,
            params.seed + k,
        )
        for k, c in enumerate(chunks)
    ]
    say(f"palpating {n} points in {len(jobs)} batch(es) on {workers} worker(s)")
    t0 = time.perf_counter()
    if workers > 1 and len(jobs) > 1:
        with _pool(workers) as pool:
            outs = list(pool.map(_simulate_batch, jobs))
    else:
        outs = [_simulate_batch(job) for job in jobs]
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
