"""Fig. 3: the fit residual against palpation time, and its exponential fit.

:func:`residual_vs_palpation_time` fits Hunt-Crossley on growing windows of
one aligned log and scores each fit on the whole log; :func:`fit_exponential`
fits r(t) = a exp(-t / tau) + c to the resulting curve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from vic_drake.errors import VicDrakeError
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
    _lstsq,
    _problem,
)
from vic_drake.estimation.signals import DEFAULT_DERIVATIVE_WINDOW_S
from vic_drake.paper import BEST_BETA


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
    """Residual of fits on growing windows, evaluated on the whole log.

    Attributes:
        window_s: (k,) palpation times (window lengths from the first
            in-contact sample), s.
        relative: (k,) relative residual on all in-contact samples of the log
            of the parameters fitted on the window.
        rms_N: (k,) the same as an RMS, N.
        kappa, lam: (k,) parameters fitted on each window.
        exp_fit: exponential fit of relative vs window_s, or None if it
            failed to converge.
        beta: exponent used.
    """

    window_s: np.ndarray
    relative: np.ndarray
    rms_N: np.ndarray
    kappa: np.ndarray
    lam: np.ndarray
    exp_fit: ExponentialFit | None
    beta: float


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


def residual_vs_palpation_time(
    data: PalpationData,
    windows_s=None,
    *,
    beta: float = BEST_BETA,
    indenter_mass_kg: float = DEFAULT_INDENTER_MASS_KG,
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
) -> ResidualCurve:
    """Relative residual against palpation time (Fig. 3 of the paper).

    For each window length T, kappa and lam are fitted on the in-contact
    samples within T seconds of the first in-contact sample; the residual of
    those parameters is then evaluated on ALL in-contact samples of the log
    (relative residual as defined in
    :mod:`vic_drake.estimation.palpation.fits`). Short windows
    generalise worse, and the curve falls towards the whole-log fit's
    residual, so more palpation time helps, as in the paper. The data must
    already be aligned (:func:`~vic_drake.estimation.palpation.data.shift`).

    Args:
        windows_s: window lengths, s; default 0.5 s to the whole log (0.5 s
            steps up to 10 s, then 2 s steps).
    """
    beta = _check_beta(beta)
    mass = _check_mass(indenter_mass_kg)
    p = _problem(
        data,
        derivative_window_s=derivative_window_s,
        min_penetration_m=DEFAULT_MIN_PENETRATION_M,
        min_force_N=DEFAULT_MIN_FORCE_N,
        spike_sigma=DEFAULT_SPIKE_SIGMA,
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
    rms_y = float(np.sqrt(np.mean(y_all**2)))
    t_masked = t_contact[p.mask]
    out = {"window": [], "rel": [], "rms": [], "kappa": [], "lam": []}
    for T in windows_s:
        sel = t_masked <= T
        if sel.sum() < 10:
            continue
        coef, _, _ = _lstsq(A_all[sel], y_all[sel])
        rms = float(np.sqrt(np.mean((y_all - A_all @ coef) ** 2)))
        out["window"].append(float(T))
        out["rel"].append(rms / rms_y)
        out["rms"].append(rms)
        out["kappa"].append(float(coef[0]))
        out["lam"].append(float(coef[1]))
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
    )
