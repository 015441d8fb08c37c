"""Fig. 3: the fit residual against palpation time, and its exponential fit.

:func:`residual_vs_palpation_time` fits Hunt-Crossley on windows of each
length (from the palpation's first sample, after the approach, or placed
all along one aligned log and averaged), scoring each fit on the whole log; :func:`fit_exponential` fits
r(t) = a exp(-t / tau) + c to the resulting curve.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation.approach import (
    DEFAULT_SETTLE_FRACTION,
    PalpationStart,
    palpation_start,
)
from vic_drake.estimation.palpation.data import (
    DEFAULT_INDENTER_MASS_KG,
    DEFAULT_MIN_FORCE_N,
    DEFAULT_MIN_PENETRATION_M,
    DEFAULT_SPIKE_SIGMA,
    PalpationData,
)
from vic_drake.estimation.palpation.fits import (
    _check_beta,
    _check_mass,
    _hc_columns,
    _problem,
    _restrict,
)
from vic_drake.estimation.signals import DEFAULT_DERIVATIVE_WINDOW_S
from vic_drake.paper import BEST_BETA

DEFAULT_START_STEP_S = 0.1
"""Spacing of the window starts when :func:`residual_vs_palpation_time`
averages over placements, s."""

AVERAGES = {
    "mean": np.mean,
    "rms": lambda v: np.sqrt(np.mean(np.square(v))),
    "median": np.median,
}
"""How :func:`residual_vs_palpation_time` combines a length's placements."""


@dataclass(frozen=True)
class ExponentialFit:
    """r(t) = a exp(-t / tau_s) + c."""

    a: float
    tau_s: float
    c: float

    def __call__(self, t_s) -> np.ndarray:
        return self.a * np.exp(-np.asarray(t_s, float) / self.tau_s) + self.c


@dataclass(frozen=True)
class ResidualCurve:
    """Residual of fits on windows of each length, evaluated on the whole log.

    Attributes:
        window_s: (k,) palpation times (window lengths), s.
        relative: (k,) relative residual on all in-contact samples of the log
            of the parameters fitted on a window of that length, averaged
            over the window's placements (``average``).
        rms_N: (k,) the same as an RMS, N (averaged likewise).
        kappa, lam: (k,) parameters fitted on the windows of each length:
            their median over the placements for ``average`` "median",
            their mean otherwise.
        exp_fit: exponential fit of relative vs window_s, or None if it
            failed to converge.
        beta: exponent used.
        n_windows: (k,) placements averaged at each length.
        start_step_s: spacing of the placements' starts, s; None for one
            window per length at the palpation's first sample.
        average: how the placements were combined (:data:`AVERAGES`).
        approach: where the palpation starts after the first in-contact
            sample (:func:`~vic_drake.estimation.palpation.approach.palpation_start`);
            ``window_s`` counts from there. None when the approach is kept.
    """

    window_s: np.ndarray
    relative: np.ndarray
    rms_N: np.ndarray
    kappa: np.ndarray
    lam: np.ndarray
    exp_fit: ExponentialFit | None
    beta: float
    n_windows: np.ndarray
    start_step_s: float | None
    average: str
    approach: PalpationStart | None = None


def fit_exponential(t_s, r, *, min_tau_s: float | None = None) -> ExponentialFit | None:
    """Robust least squares of r(t) = a exp(-t/tau) + c.

    Soft-L1 loss (scale: a tenth of the spread of r), so a few windows that
    happen to generalise unusually well or badly (e.g. one holding only the
    approach transient) do not bend the curve; tau is bounded below by
    ``min_tau_s`` (default: the smallest t, since a decay faster than the
    first sample is not resolved by the data).

    Returns:
        The fit, or None with fewer than 4 points or no convergence.
    """
    t_s = np.asarray(t_s, float)
    r = np.asarray(r, float)
    if t_s.size < 4 or not np.all(np.isfinite(r)):
        return None
    min_tau = float(t_s.min() if min_tau_s is None else min_tau_s)
    min_tau = max(min_tau, 1e-6)
    order = np.argsort(t_s)
    quarter = max(t_s.size // 4, 1)
    c0 = float(np.median(r[order[-quarter:]]))
    a0 = float(np.median(r[order[:quarter]]) - c0)
    if a0 == 0.0:
        a0 = 1e-12
    tau0 = float(max((t_s.max() - t_s.min()) / 5.0, min_tau * 1.01))
    spread = float(np.ptp(r))
    if spread == 0.0:
        return ExponentialFit(a=0.0, tau_s=tau0, c=float(r[0]))

    def resid(x):
        a, tau, c = x
        return a * np.exp(-t_s / tau) + c - r

    res = least_squares(
        resid,
        x0=(a0, tau0, c0),
        bounds=([-np.inf, min_tau, -np.inf], [np.inf, np.inf, np.inf]),
        loss="soft_l1",
        f_scale=0.1 * spread,
        x_scale=(max(abs(a0), 1e-12), tau0, max(abs(c0), 1e-12)),
        max_nfev=20000,
    )
    if not res.success:
        return None
    a, tau, c = res.x
    return ExponentialFit(a=float(a), tau_s=float(tau), c=float(c))


def _check_start_step(start_step_s) -> float | None:
    if start_step_s is None:
        return None
    try:
        step = float(start_step_s)
    except (TypeError, ValueError):
        step = math.nan
    if not (math.isfinite(step) and step > 0.0):
        raise VicDrakeError(
            f"start_step_s must be a positive number of seconds or None (one window "
            f"at the first in-contact sample); got {start_step_s!r}"
        )
    return step


def _window_starts(T: float, total: float, step: float | None) -> np.ndarray:
    """Start times (s after the palpation's first sample) of the windows of
    length ``T`` that lie inside a log of ``total`` in-contact seconds."""
    if step is None or T >= total:
        return np.zeros(1)
    return step * np.arange(int(np.floor((total - T) / step + 1e-9)) + 1)


def residual_vs_palpation_time(
    data: PalpationData,
    windows_s=None,
    *,
    beta: float = BEST_BETA,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
    start_step_s: float | None = None,
    average: str = "mean",
    skip_approach: bool = True,
    settle_fraction: float = DEFAULT_SETTLE_FRACTION,
) -> ResidualCurve:
    """Relative residual against palpation time (Fig. 3 of the paper).

    The palpation starts where its approach ends (``skip_approach``, the
    default): the whole cycles in which the probe still sinks towards its
    operating depth are left out of the fits and of the scoring
    (:func:`~vic_drake.estimation.palpation.approach.palpation_start`); a
    log with no clear oscillation keeps all its samples.
    For each window length T, kappa and lam are fitted on the in-contact
    samples within T seconds of the palpation's first sample (the default,
    ``start_step_s=None``) or, with ``start_step_s``, on every window
    [s, s + T] that fits in the log, with starts s every ``start_step_s``
    seconds from the palpation's first sample. The residual of each window's
    parameters is evaluated on ALL in-contact samples of the log (relative
    residual as defined in :mod:`vic_drake.estimation.palpation.fits`); with
    several placements the curve holds their mean (``average``), the
    whole-log residual to expect from a palpation of T seconds placed
    anywhere in the log (a learning curve). The whole-log
    least-squares fit has the smallest whole-log residual, and a window's
    residual exceeds it by the distance of the window's parameters from the
    whole-log ones, measured on the log's own samples; so the curve falls
    towards the whole-log fit's residual as the window's estimate becomes
    more precise, as in the paper. The data must already be aligned
    (:func:`~vic_drake.estimation.palpation.data.shift`).

    Args:
        windows_s: window lengths, s; default 0.5 s to the whole log (0.5 s
            steps up to 10 s, then 2 s steps).
        start_step_s: spacing of the window starts, s (e.g.
            :data:`DEFAULT_START_STEP_S`); None (default) places one window
            per length, at the palpation's first sample.
        average: how the placements' residuals (and parameters) are
            combined: "mean", "rms" or "median" (see :data:`AVERAGES`).
        skip_approach: leave out the approach (default); False counts from
            the first in-contact sample.
        settle_fraction: when the approach is over (see
            :data:`~vic_drake.estimation.palpation.approach.DEFAULT_SETTLE_FRACTION`).
    """
    beta = _check_beta(beta)
    mass = _check_mass(indenter_mass_kg)
    step = _check_start_step(start_step_s)
    if not isinstance(average, str) or average not in AVERAGES:
        raise VicDrakeError(
            f"average must be one of {sorted(AVERAGES)}; got {average!r}"
        )
    combine = AVERAGES[average]
    central = np.median if average == "median" else np.mean
    p = _problem(
        data,
        derivative_window_s=derivative_window_s,
        min_penetration_m=DEFAULT_MIN_PENETRATION_M,
        min_force_N=DEFAULT_MIN_FORCE_N,
        spike_sigma=DEFAULT_SPIKE_SIGMA,
    )
    approach = None
    if skip_approach:
        approach = palpation_start(
            data.t_s,
            p.eps,
            p.mask,
            z_target_m=data.z_target_m,
            settle_fraction=settle_fraction,
        )
        if approach.cycles_skipped:
            t_start = data.t_s[np.argmax(p.mask)] + approach.start_s
            p = _restrict(
                p,
                data.t_s >= t_start - 1e-9,
                min_penetration_m=DEFAULT_MIN_PENETRATION_M,
                min_force_N=DEFAULT_MIN_FORCE_N,
            )
    t_contact = data.t_s - data.t_s[np.argmax(p.mask)]
    total = float(t_contact[p.mask][-1])
    if windows_s is None:
        windows_s = np.concatenate(
            [
                np.arange(0.5, min(total, 10.0), 0.5),
                np.arange(10.0, total, 2.0),
                [total],
            ]
        )
    windows_s = np.unique(np.asarray(windows_s, float))
    if windows_s.size == 0 or not np.all(windows_s > 0):
        raise VicDrakeError(f"windows_s must be positive lengths; got {windows_s!r}")
    A_all = _hc_columns(p, beta)
    y_all = p.target(mass)
    t_masked = t_contact[p.mask]
    n = y_all.size
    rms_y = float(np.sqrt(np.mean(y_all**2)))
    # Normal equations of every window from prefix sums, in scaled columns
    # (eps^beta ~ 1e-3 and eps^beta eps_dot ~ 1e-5 differ a lot).
    scale = np.sqrt(np.mean(A_all**2, axis=0))
    scale[scale == 0.0] = 1.0
    As = A_all / scale
    gram = np.zeros((n + 1, 2, 2))
    gram[1:] = np.cumsum(As[:, :, None] * As[:, None, :], axis=0)
    moment = np.zeros((n + 1, 2))
    moment[1:] = np.cumsum(As * y_all[:, None], axis=0)
    # Whole-log fit: residual sum of squares of any x is rss_best plus
    # (x - x_best)' G (x - x_best), G the whole log's scaled Gram matrix.
    x_best = np.linalg.pinv(gram[-1]) @ moment[-1]
    rss_best = float(np.sum((y_all - As @ x_best) ** 2))
    out = {"window": [], "rel": [], "rms": [], "kappa": [], "lam": [], "count": []}
    for T in windows_s:
        starts = _window_starts(float(T), total, step)
        i0 = np.searchsorted(t_masked, starts, side="left")
        i1 = np.searchsorted(t_masked, starts + T, side="right")
        ok = i1 - i0 >= 10
        if not ok.any():
            continue
        i0, i1 = i0[ok], i1[ok]
        x = np.einsum(
            "kij,kj->ki", np.linalg.pinv(gram[i1] - gram[i0]), moment[i1] - moment[i0]
        )
        dx = x - x_best
        rss = rss_best + np.einsum("ki,ij,kj->k", dx, gram[-1], dx)
        rms = np.sqrt(np.maximum(rss, 0.0) / n)
        coef = x / scale
        out["window"].append(float(T))
        out["rel"].append(float(combine(rms)) / rms_y)
        out["rms"].append(float(combine(rms)))
        out["kappa"].append(float(central(coef[:, 0])))
        out["lam"].append(float(central(coef[:, 1])))
        out["count"].append(int(i0.size))
    if not out["window"]:
        raise VicDrakeError("no window holds enough in-contact samples to fit")
    window = np.array(out["window"])
    rel = np.array(out["rel"])
    return ResidualCurve(
        window_s=window,
        relative=rel,
        rms_N=np.array(out["rms"]),
        kappa=np.array(out["kappa"]),
        lam=np.array(out["lam"]),
        exp_fit=fit_exponential(window, rel),
        beta=beta,
        n_windows=np.array(out["count"]),
        start_step_s=step,
        average=average,
        approach=approach,
    )
