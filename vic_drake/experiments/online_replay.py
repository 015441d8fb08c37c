"""Replaying a real log through an online estimator, scored against a reference.

:func:`replay_online` reads a bag and runs the estimator tick by tick
(:func:`vic_drake.estimation.online.run_online`):

- a 6-column palpation log: the reference is the offline least-squares
  Hunt-Crossley fit of the whole log (:func:`fit_hunt_crossley` at the
  estimator's beta, after the sensor lag of
  :func:`~vic_drake.estimation.palpation.estimate_lag`, as
  ``vic-drake fit-palpation`` reports it). The surface is the log's.
- a 31-column log of the variable-impedance controller (a VS scan): the
  reference is the GP map's kappa and lam that the controller logged at
  each tick (its nearest map point); the surface input is the one it acted
  on, the tip height plus its logged penetration. No map file is needed.

The estimator pairs each force sample with the position of ``lag_s``
earlier (a delay line, causal): by default the offline lag estimate on a
palpation (the same alignment as its reference) and 0 on a scan.

Scores, over the samples in contact (the estimator's contact rule):
median relative errors of kappa and lam, the correlation of kappa with the
reference (NaN when the reference is one number), the convergence time
(from the first contact until kappa stays within 10 % of the reference) and
the 99th percentile of the tick's wall time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online import (
    OnlineEstimatorParams,
    OnlineTrace,
    convergence_time_s,
    relative_errors,
    run_online,
)
from vic_drake.realdata import CONTROLLER_COLUMNS, LAYOUTS, read_bag

#: Layouts the replay accepts (see vic_drake.realdata.LAYOUTS).
REPLAY_LAYOUTS = ("palpation", "controller")


@dataclass(frozen=True)
class OnlineReplay:
    """One log replayed.

    Attributes:
        kind: "palpation" or "scan".
        trace: the estimator's outputs per sample.
        kappa_ref, lam_ref: (n,) reference per sample.
        lag_s: the delay paired with the force, s.
        summary: the scores (keys of ``vic-drake estimate-online --json``).
        final_kappa_rel_err: relative error at the last sample in contact.
    """

    kind: str
    trace: OnlineTrace
    kappa_ref: np.ndarray
    lam_ref: np.ndarray
    lag_s: float
    summary: dict
    final_kappa_rel_err: float


def _delay(values: np.ndarray, d: int) -> np.ndarray:
    """values[k - d] at k (NaN for the first d samples)."""
    if d == 0:
        return values
    out = np.full_like(values, np.nan)
    out[d:] = values[:-d]
    return out


def _palpation_inputs(df, params, lag_s):
    from vic_drake.estimation.palpation import (
        PalpationData,
        estimate_lag,
        fit_hunt_crossley,
        shift,
    )

    data = PalpationData.from_frame(df)
    if lag_s is None:
        lag_s = estimate_lag(data)
    fit = fit_hunt_crossley(shift(data, lag_s), beta=params.beta)
    rows = df[["t_s", "vz_m_per_s"]].to_numpy(float)
    ok = np.all(np.isfinite(rows), axis=1)
    vz = np.interp(data.t_s, rows[ok, 0], rows[ok, 1])
    n = data.n
    inputs = (data.t_s, data.z_m, vz, data.force_N, data.surface_array_m)
    return inputs, np.full(n, fit.kappa), np.full(n, fit.lam), lag_s


def _scan_inputs(df, lag_s):
    t = df["t_s"].to_numpy(float)
    z = df["z_m"].to_numpy(float)
    # The surface the controller acted on: its logged penetration is measured
    # from the map's nearest grid point + 0.0025 m, 1.5 mm above the tip's
    # logged z plus our bilinear map (docs/decisions.md, "Online replay on
    # scan logs: the controller's own surface").
    surface = z + df["penetration_m"].to_numpy(float)
    force = -df["sensor_force_z_N"].to_numpy(float)
    inputs = (t, z, df["vz_m_per_s"].to_numpy(float), force, surface)
    return (
        inputs,
        df["kappa_N_per_m_beta"].to_numpy(float),
        df["lambda_N_s_per_m_beta1"].to_numpy(float),
        (0.0 if lag_s is None else lag_s),
    )


def replay_online(
    bag,
    *,
    params: OnlineEstimatorParams | None = None,
    lag_s: float | None = None,
) -> OnlineReplay:
    """Runs the online estimator over a real log and scores it.

    Args:
        bag: the bag folder (6-column palpation or 31-column controller log).
        params: estimator settings (default: RLS defaults).
        lag_s: force-after-position delay, s (>= 0); None = the default of
            the log's kind (module docstring).

    Raises:
        VicDrakeError: another layout, a bad lag, too few samples in
            contact.
    """
    params = OnlineEstimatorParams() if params is None else params
    params.validate()
    kind, inputs, kappa_ref, lam_ref, lag = replay_inputs(bag, params, lag_s)
    trace = run_online(*inputs, params)
    return score_online(kind, trace, kappa_ref, lam_ref, lag, params)


def replay_inputs(bag, params: OnlineEstimatorParams, lag_s: float | None = None):
    """What :func:`replay_online` feeds the estimator, and its reference.

    Returns:
        (kind, (t, z, z_dot, force, surface) as :func:`run_online` takes
        them, with z, z_dot and the surface delayed by the lag; kappa_ref,
        lam_ref, lag_s). ``params`` gives the palpation reference's beta.
    """
    if lag_s is not None and not (np.isfinite(lag_s) and 0.0 <= lag_s <= 1.0):
        raise VicDrakeError(f"lag_s must be in [0, 1] s; got {lag_s!r}")
    df = read_bag(bag)
    layout = df.attrs["layout"]
    if layout not in REPLAY_LAYOUTS:
        widths = {name: len(cols) for name, cols in LAYOUTS.values()}
        raise VicDrakeError(
            f"bag {str(bag)!r} holds the {layout!r} layout ({widths[layout]} columns); "
            "the online replay needs a palpation log (6 columns) or a variable-"
            f"impedance scan log ({len(CONTROLLER_COLUMNS)} columns): the CS/CF scan "
            "logs carry no map-referenced surface to compare with"
        )
    if layout == "palpation":
        kind = "palpation"
        inputs, kappa_ref, lam_ref, lag = _palpation_inputs(df, params, lag_s)
    else:
        kind = "scan"
        inputs, kappa_ref, lam_ref, lag = _scan_inputs(df, lag_s)
    t, z, vz, force, surface = inputs
    period = float(np.median(np.diff(t)))
    d = int(round(lag / period)) if period > 0 else 0
    inputs = (t, _delay(z, d), _delay(vz, d), force, _delay(surface, d))
    return kind, inputs, kappa_ref, lam_ref, lag


def score_online(kind, trace, kappa_ref, lam_ref, lag, params) -> OnlineReplay:
    """The replay's scores (the ``--json`` keys) of a trace against its reference."""
    contact = trace.column("in_contact") > 0.5
    if contact.sum() < 10:
        raise VicDrakeError(
            f"only {int(contact.sum())} samples in contact (force > "
            f"{params.contact_threshold_N:g} N, penetration > "
            f"{params.min_penetration_m * 1e3:g} mm); nothing to estimate"
        )
    k_err = relative_errors(trace.kappa, kappa_ref, contact)
    l_err = relative_errors(trace.lam, lam_ref, contact)
    corr = float("nan")
    ref_c = kappa_ref[contact]
    if np.ptp(ref_c) > 0.0:
        corr = float(np.corrcoef(trace.kappa[contact], ref_c)[0, 1])
    last = int(np.flatnonzero(contact)[-1])
    final = abs(trace.kappa[last] - kappa_ref[last]) / abs(kappa_ref[last])
    summary = {
        "method": params.method,
        "samples": int(trace.t_s.size),
        "kappa_rel_err_median": float(np.median(k_err)),
        "kappa_corr": corr,
        "lambda_rel_err_median": float(np.median(l_err)),
        "convergence_s": convergence_time_s(trace.t_s, trace.kappa, kappa_ref, contact),
        "tick_us_p99": float(np.percentile(trace.tick_s, 99) * 1e6),
    }
    return OnlineReplay(kind, trace, kappa_ref, lam_ref, lag, summary, float(final))


__all__ = [
    "REPLAY_LAYOUTS",
    "OnlineReplay",
    "replay_inputs",
    "replay_online",
    "score_online",
]
