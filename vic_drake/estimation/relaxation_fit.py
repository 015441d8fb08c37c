"""Identifies the relaxing Hunt-Crossley law from palpation and load-test logs.

The law is :mod:`vic_drake.tissue.relaxation`: with u = max(eps, 0)^beta and
branch states s_i (u through first-order lags of time constants tau_i),

    F_sensor + m_I z_ddot = kappa (u - sum_i g_i s_i) + lam u eps_dot.

The relaxation shape (g_i, tau_i) is a property of the material and is
shared by all logs of a fit; kappa and lam belong to the point palpated and
are fitted per log. The fit is a variable projection: for given (g, tau)
each log's (kappa, lam) solve a linear least-squares problem, and
(log tau, g) are found by nonlinear least squares (from three starts) over
all logs, each log weighted by 1 / sqrt(its samples) so that long logs do
not dominate. The
states run over every sample of the aligned log from its start (the probe
starts out of contact, states zero); the residual is taken over the
in-contact samples of the plain fits
(:func:`~vic_drake.estimation.palpation.data.contact_mask`).

:func:`held_out_errors` scores the law on logs it was not fitted on against
plain Hunt-Crossley at the same beta: both refit their (kappa, lam) on the
held-out log (two linear parameters each), the relaxing law keeps the
(g, tau) of the training logs; the RMS errors of the two are the test.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.loadtest import load_test_phases
from vic_drake.estimation.palpation.data import (
    DEFAULT_INDENTER_MASS_KG,
    PalpationData,
    contact_mask,
    kinematics,
)
from vic_drake.estimation.palpation.fits import MIN_CONTACT_SAMPLES, _check_beta
from vic_drake.estimation.signals import DEFAULT_DERIVATIVE_WINDOW_S
from vic_drake.paper import BEST_BETA
from vic_drake.tissue.relaxation import (
    RelaxationParams,
    relaxation_history,
    relaxation_input,
)

#: Starting time constants of the fit, s (their count is the number of
#: branches). One branch: on the paper's palpations a second or third branch
#: lowers no log's residual (docs/decisions.md, "Tissue relaxation").
DEFAULT_INITIAL_TIME_CONSTANTS_S = (5.0,)

#: The fit also starts from the initial time constants times these factors.
START_FACTORS = (0.2, 1.0, 5.0)

#: Lower bound of every tau_i, s: the derivative window
#: (:data:`~vic_drake.estimation.signals.DEFAULT_DERIVATIVE_WINDOW_S`); a
#: faster relaxation is not told apart from the viscous term there.
MIN_TIME_CONSTANT_S = DEFAULT_DERIVATIVE_WINDOW_S

#: Upper bound of sum g_i in the fit: the relaxed modulus keeps at least a
#: tenth of the instantaneous one (the law needs sum g_i < 1).
MAX_RELAXING_FRACTION = 0.9


@dataclass
class _Log:
    """One aligned log reduced to what the fit needs."""

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray  # u * eps_dot
    y: np.ndarray  # F + m_I z_ddot
    mask: np.ndarray

    def states(self, taus) -> np.ndarray:
        return relaxation_history(self.t, self.u, taus)[self.mask]


def _reduce(
    data: PalpationData, beta: float, mass: float, window_s: float, mask=None
) -> _Log:
    kin = kinematics(data, window_s=window_s)
    if mask is None:
        mask = contact_mask(data, kin)
    mask = np.asarray(mask, bool)
    if mask.sum() < MIN_CONTACT_SAMPLES:
        raise VicDrakeError(
            f"a relaxation fit needs >= {MIN_CONTACT_SAMPLES} in-contact samples per "
            f"log, got {int(mask.sum())}"
        )
    u = relaxation_input(kin.eps_m, beta)
    u = np.where(np.isfinite(u), u, 0.0)
    return _Log(
        t=data.t_s,
        u=u,
        v=(u * kin.eps_dot_m_per_s)[mask],
        y=(data.force_N + mass * kin.z_ddot_m_per_s2)[mask],
        mask=mask,
    )


def _solve(log: _Log, elastic: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(kappa, lam) of y = kappa elastic + lam v, and the residual."""
    A = np.column_stack([elastic, log.v])
    scale = np.sqrt(np.mean(A**2, axis=0))
    scale[scale == 0.0] = 1.0
    coef, *_ = np.linalg.lstsq(A / scale, log.y, rcond=None)
    coef = coef / scale
    return coef, log.y - A @ coef


@dataclass(frozen=True)
class RelaxationFit:
    """The relaxing law fitted on a set of logs.

    Attributes:
        relaxation: the shared (g_i, tau_i).
        beta: the fixed exponent.
        kappa: {log: instantaneous kappa}, N/m^beta. lam: {log: lam}.
        rms_N: {log: RMS residual}, N.
        hc_kappa, hc_lam, hc_rms_N: {log: value} of the plain HC fit on the
            same samples.
        indenter_mass_kg: m_I used.
    """

    relaxation: RelaxationParams
    beta: float
    kappa: dict
    lam: dict
    rms_N: dict
    hc_kappa: dict
    hc_lam: dict
    hc_rms_N: dict
    indenter_mass_kg: float


def fit_relaxation(
    logs: dict,
    *,
    beta: float = BEST_BETA,
    initial_time_constants_s=DEFAULT_INITIAL_TIME_CONSTANTS_S,
    max_time_constant_s: float | None = None,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
) -> RelaxationFit:
    """Fits the shared relaxation and per-log (kappa, lam) (see module doc).

    Args:
        logs: {name: PalpationData}, each already aligned
            (:func:`~vic_drake.estimation.palpation.data.shift`) and starting
            out of contact.
        beta: Hunt-Crossley exponent.
        initial_time_constants_s: starting tau_i (their count is the number
            of branches).
        max_time_constant_s: upper bound of every tau_i, s; default the
            longest log's length (a slower decay is not identified by them).

    Raises:
        VicDrakeError: no logs, bad beta or time constants, or a log with too
            few in-contact samples.
    """
    beta = _check_beta(beta)
    if not logs:
        raise VicDrakeError("fit_relaxation needs at least one log")
    tau0 = np.atleast_1d(np.asarray(initial_time_constants_s, float))
    if tau0.size == 0 or not np.all(np.isfinite(tau0) & (tau0 > 0)):
        raise VicDrakeError(
            f"initial_time_constants_s must be > 0, got {initial_time_constants_s!r}"
        )
    k = tau0.size
    reduced = {
        name: _reduce(d, beta, indenter_mass_kg, derivative_window_s)
        for name, d in logs.items()
    }
    cache: dict = {}

    def states(name, taus):
        key = (name, tuple(np.round(taus, 12)))
        if len(cache) > 4 * len(reduced):  # Keep the last few (memory).
            cache.clear()
        if key not in cache:
            cache[key] = reduced[name].states(taus)
        return cache[key]

    def per_log(x):
        taus, g = np.exp(x[:k]), x[k:]
        out = {}
        for name, log in reduced.items():
            elastic = log.u[log.mask] - states(name, taus) @ g
            out[name] = _solve(log, elastic)
        return out

    def residual(x):
        return np.concatenate([r / np.sqrt(r.size) for _, r in per_log(x).values()])

    lower = np.concatenate([np.full(k, np.log(MIN_TIME_CONSTANT_S)), np.zeros(k)])
    if max_time_constant_s is None:
        max_time_constant_s = max(float(np.ptp(d.t_s)) for d in logs.values())
    if not (np.isfinite(max_time_constant_s) and max_time_constant_s > np.max(tau0)):
        raise VicDrakeError(
            "max_time_constant_s must exceed every initial time constant, got "
            f"{max_time_constant_s!r}"
        )
    upper = np.concatenate(
        [np.full(k, np.log(max_time_constant_s)), np.full(k, MAX_RELAXING_FRACTION / k)]
    )
    # The cost has local minima in tau (a fast branch trades with lam): the
    # fit starts from the given time constants and from 5x either side, and
    # keeps the best.
    starts = [
        np.concatenate(
            [np.clip(np.log(tau0 * f), lower[:k], upper[:k] - 1e-9), np.full(k, 0.05)]
        )
        for f in START_FACTORS
    ]
    res = min(
        (least_squares(residual, x0, bounds=(lower, upper)) for x0 in starts),
        key=lambda r: r.cost,
    )
    order = np.argsort(res.x[:k])
    taus, g = np.exp(res.x[:k])[order], res.x[k:][order]
    solved = per_log(np.concatenate([np.log(taus), g]))
    hc = {name: _solve(log, log.u[log.mask]) for name, log in reduced.items()}

    def rms(r):
        return float(np.sqrt(np.mean(r**2)))

    return RelaxationFit(
        relaxation=RelaxationParams(tuple(g), tuple(taus)),
        beta=beta,
        kappa={n: float(c[0]) for n, (c, _) in solved.items()},
        lam={n: float(c[1]) for n, (c, _) in solved.items()},
        rms_N={n: rms(r) for n, (_, r) in solved.items()},
        hc_kappa={n: float(c[0]) for n, (c, _) in hc.items()},
        hc_lam={n: float(c[1]) for n, (c, _) in hc.items()},
        hc_rms_N={n: rms(r) for n, (_, r) in hc.items()},
        indenter_mass_kg=float(indenter_mass_kg),
    )


@dataclass(frozen=True)
class HeldOutError:
    """RMS force errors of the two laws on one held-out log, N.

    Attributes:
        relaxing_rms_N: the relaxing law (training (g, tau), refitted
            kappa, lam). hc_rms_N: plain Hunt-Crossley (refitted kappa, lam).
        kappa, lam: the relaxing law's refit. hc_kappa, hc_lam: HC's.
        n_samples: samples scored.
        phases: for a load test (:func:`~vic_drake.estimation.loadtest.load_test_phases`),
            {phase: {"samples", "rms_N", "hc_rms_N", "mean_N", "hc_mean_N"}}
            over the scored samples of each phase, where mean is the mean of
            measured minus model (> 0: the log's force is above the law's);
            else None.
    """

    relaxing_rms_N: float
    hc_rms_N: float
    kappa: float
    lam: float
    hc_kappa: float
    hc_lam: float
    n_samples: int
    phases: dict | None = None


def held_out_errors(
    relaxation: RelaxationParams,
    logs: dict,
    *,
    beta: float = BEST_BETA,
    masks: dict | None = None,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
) -> dict:
    """Scores a fixed relaxation against plain HC on logs (see module doc).

    Args:
        relaxation: (g, tau) identified elsewhere.
        logs: {name: aligned PalpationData}.
        masks: optional {name: (n,) bool} of the samples to score (default:
            the in-contact samples of the plain fits).

    Returns:
        {name: :class:`HeldOutError`}.
    """
    beta = _check_beta(beta)
    masks = masks or {}
    out = {}
    g = np.asarray(relaxation.fractions)
    for name, data in logs.items():
        log = _reduce(
            data, beta, indenter_mass_kg, derivative_window_s, masks.get(name)
        )
        u = log.u[log.mask]
        (kappa, lam), r = _solve(log, u - log.states(relaxation.time_constants_s) @ g)
        (hc_kappa, hc_lam), r_hc = _solve(log, u)
        out[name] = HeldOutError(
            relaxing_rms_N=float(np.sqrt(np.mean(r**2))),
            hc_rms_N=float(np.sqrt(np.mean(r_hc**2))),
            kappa=float(kappa),
            lam=float(lam),
            hc_kappa=float(hc_kappa),
            hc_lam=float(hc_lam),
            n_samples=int(log.mask.sum()),
            phases=_phase_errors(data, log.mask, r, r_hc),
        )
    return out


def _phase_errors(data: PalpationData, mask, r, r_hc) -> dict | None:
    """Per-phase RMS and mean residuals of a load test (None otherwise)."""
    phases = load_test_phases(data.t_s, data.z_target_m)
    if phases is None:
        return None
    out = {}
    for phase, where in phases.items():
        sel = where[mask]
        if not sel.any():
            continue
        out[phase] = {
            "samples": int(sel.sum()),
            "rms_N": float(np.sqrt(np.mean(r[sel] ** 2))),
            "hc_rms_N": float(np.sqrt(np.mean(r_hc[sel] ** 2))),
            "mean_N": float(np.mean(r[sel])),
            "hc_mean_N": float(np.mean(r_hc[sel])),
        }
    return out


__all__ = [
    "DEFAULT_INITIAL_TIME_CONSTANTS_S",
    "MAX_RELAXING_FRACTION",
    "MIN_TIME_CONSTANT_S",
    "START_FACTORS",
    "HeldOutError",
    "RelaxationFit",
    "fit_relaxation",
    "held_out_errors",
    "predict_force",
]


def predict_force(
    relaxation: RelaxationParams | None,
    kappa: float,
    lam: float,
    data: PalpationData,
    *,
    beta: float = BEST_BETA,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
) -> np.ndarray:
    """The force the sensor would read along a logged trajectory, N.

    The relaxing law (None: plain HC) with the given kappa, lam, driven by
    the measured tip trajectory of ``data`` from its first sample (states
    zero), tissue force clipped at 0, minus m_I z_ddot
    (:attr:`PalpationData.force_N` convention; the logged force is unused).
    """
    beta = _check_beta(beta)
    kin = kinematics(data, window_s=derivative_window_s)
    u = relaxation_input(kin.eps_m, beta)
    elastic = u
    if relaxation is not None and relaxation.n_branches:
        states = relaxation_history(data.t_s, u, relaxation.time_constants_s)
        elastic = u - states @ np.asarray(relaxation.fractions)
    tissue = kappa * elastic + lam * u * kin.eps_dot_m_per_s
    tissue = np.maximum(np.where(kin.eps_m > 0.0, tissue, 0.0), 0.0)
    return tissue - indenter_mass_kg * kin.z_ddot_m_per_s2
