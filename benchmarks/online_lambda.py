"""Why the online estimators' lambda wanders on the VS scans (issue 12).

Replays the five real logs as ``vic-drake estimate-online`` does and prints,
per log:

- ``excitation``: the information per second of kappa's and lambda's
  regressors (normalised to the priors, at ``noise_std_N``), lambda's
  information given kappa (the Schur complement of the 2 x 2 information
  over 2 s windows, the RLS's memory), the RLS's and the EKF's lambda
  variance as a fraction of the prior's, lambda_hat / lam_prior
  percentiles, and how the RLS's lambda moves split by |eps_dot|.
- ``batch``: offline least squares of each scan with one kappa per window
  (0.25 s, 1 s: the map's kappa moves along the path) and one lambda for
  the whole scan, at force-position delays of 0 to 40 ms: the lambda the
  scan's data support, against the map's.
- ``held``: the RLS with lambda held at the prior (its covariance row
  zeroed after every step): what lambda's wandering costs kappa.

    python benchmarks/online_lambda.py [--section S] [--data-dir DIR]
"""

from __future__ import annotations

import numpy as np
from common import run_sections

from vic_drake.estimation.online import OnlineEstimatorParams
from vic_drake.estimation.online.core import AUX_SIZE, S_DOT
from vic_drake.estimation.online.replay import estimator_functions, run_online
from vic_drake.experiments.online_replay import replay_inputs, score_online

LOGS = (
    "palpation/test_soft_1hz",
    "palpation/test_soft_2hz",
    "palpation/test_soft_25hz",
    "experiments/test_tracking5",
    "experiments/test_nardi_matForce_lowR",
)
SCANS = LOGS[3:]
EPS_DOT_BINS_MM_S = (0.0, 1.0, 2.0, 5.0, 10.0, 20.0, np.inf)


def _trace(inputs, params):
    """Per sample in contact: (eps, eps_dot, x0, x1, P00, P11, dx1)."""
    t, z, vz, f, s = inputs
    init, step = estimator_functions(params)
    state = init(params)
    i_x = AUX_SIZE
    rows = []
    for k in range(t.size):
        lam_before = state[i_x + 1]
        state, est = step(state, t[k], z[k], vz[k], f[k], s[k], params)
        if est.in_contact > 0.5:
            n = 2 if params.method == "rls" else _size(state)
            p0 = AUX_SIZE + n
            rows.append(
                (
                    est.surface_z_m - z[k],
                    state[S_DOT] - vz[k],
                    state[i_x],
                    state[i_x + 1],
                    state[p0],
                    state[p0 + n + 1],
                    state[i_x + 1] - lam_before,
                )
            )
    return np.array(rows)


def _size(state) -> int:
    """n of an EKF state without the slope fit (AUX + 2 (n + n^2) entries)."""
    m = (len(state) - AUX_SIZE) // 2
    return int(round((-1 + np.sqrt(1 + 4 * m)) / 2))


def excitation_section(data_dir) -> None:
    for log in LOGS:
        p = OnlineEstimatorParams()
        _, inputs, _, lam_ref, _ = replay_inputs(data_dir / log, p)
        dt = float(np.median(np.diff(inputs[0])))
        cap = p.prior_rel_std**2
        print(f"{log}:")
        for method in ("rls", "ekf"):
            params = OnlineEstimatorParams(method=method)
            r = _trace(inputs, params)
            e_b = r[:, 0] ** p.beta
            hk = p.kappa_prior * e_b / p.noise_std_N
            hl = p.lam_prior * e_b * r[:, 1] / p.noise_std_N
            if method == "rls":
                win = max(1, int(round(p.memory_s / dt)))
                schur = []
                for a in range(0, len(r) - win, win):
                    kk, kl, ll = (
                        np.sum(hk[a : a + win] ** 2),
                        np.sum(hk[a : a + win] * hl[a : a + win]),
                        np.sum(hl[a : a + win] ** 2),
                    )
                    schur.append(ll - kl * kl / kk)
                print(
                    f"  information per s: kappa {np.mean(hk**2) / dt:.3g}, lambda "
                    f"{np.mean(hl**2) / dt:.3g}; lambda given kappa per "
                    f"{p.memory_s:g} s window: median {np.median(schur):.3g} "
                    f"(prior {1 / cap:.3g}); |eps_dot| p50/p90 "
                    f"{np.percentile(np.abs(r[:, 1]) * 1e3, 50):.1f}/"
                    f"{np.percentile(np.abs(r[:, 1]) * 1e3, 90):.1f} mm/s"
                )
            lam = r[:, 3]
            print(
                f"  {method}: P_lam / prior var p10/50/90 "
                + "/".join(
                    f"{v:.3f}" for v in np.percentile(r[:, 5] / cap, [10, 50, 90])
                )
                + "; lambda_hat / lam_prior p5/50/95/max "
                + "/".join(f"{v:.2f}" for v in np.percentile(lam, [5, 50, 95, 100]))
                + f" (map median {np.nanmedian(lam_ref) / p.lam_prior:.2f})"
            )
            if method == "rls":
                ae = np.abs(r[:, 1]) * 1e3
                cells = []
                for lo, hi in zip(EPS_DOT_BINS_MM_S[:-1], EPS_DOT_BINS_MM_S[1:]):
                    m = (ae >= lo) & (ae < hi)
                    cells.append(
                        f"{lo:g}-{hi:g}: {m.mean():.3f} of samples, "
                        f"{np.abs(r[m, 6]).sum():.1f}"
                    )
                print("  rls sum |d lambda_hat| by |eps_dot| mm/s: " + "; ".join(cells))


def batch_section(data_dir) -> None:
    p = OnlineEstimatorParams()
    for log in SCANS:
        for lag in (0.0, 0.01, 0.02, 0.04):
            _, (t, z, vz, f, s), _, lam_ref, _ = replay_inputs(data_dir / log, p, lag)
            eps = s - z
            eps_dot = np.gradient(s, t) - vz
            ok = (f > p.contact_threshold_N) & (eps > p.min_penetration_m)
            ok &= np.isfinite(f + eps + eps_dot)
            rows = np.flatnonzero(ok)
            e_b = eps[rows] ** p.beta
            cells = []
            for width in (0.25, 1.0):
                w = np.floor((t[rows] - t[0]) / width).astype(int)
                _, col = np.unique(w, return_inverse=True)
                a = np.zeros((rows.size, col.max() + 2))
                a[np.arange(rows.size), col] = e_b
                a[:, -1] = e_b * eps_dot[rows]
                sol = np.linalg.lstsq(a, f[rows], rcond=None)[0]
                cells.append(f"kappa per {width:g} s: lambda {sol[-1]:.0f}")
            print(
                f"{log} lag {lag * 1e3:.0f} ms: "
                + ", ".join(cells)
                + f"; map median {np.nanmedian(lam_ref[ok]):.0f}, prior {p.lam_prior:.0f}"
            )


def _hold_lambda(state, n=2):
    """Zeroes lambda's row and column of P (lambda_hat then never moves)."""
    p0 = AUX_SIZE + n
    state[p0 + 1] = state[p0 + 2] = state[p0 + 3] = 0.0
    return state


def _held(init, step):
    """The RLS's (initial state, step) with lambda held at the prior."""

    def held_init(params):
        return _hold_lambda(init(params))

    def held_step(state, *args):
        state, est = step(state, *args)
        return _hold_lambda(state), est

    return held_init, held_step


def held_section(data_dir) -> None:
    import vic_drake.estimation.online.replay as replay

    params = OnlineEstimatorParams()
    original = replay.estimator_functions
    for log in LOGS:
        kind, inputs, k_ref, l_ref, lag = replay_inputs(data_dir / log, params)
        cells = []
        for label, held in (("rls", False), ("rls, lambda held", True)):
            if held:
                pair = _held(*original(params))
                replay.estimator_functions = lambda _p, pair=pair: pair
            try:
                trace = run_online(*inputs, params)
            finally:
                replay.estimator_functions = original
            s = score_online(kind, trace, k_ref, l_ref, lag, params).summary
            cells.append(
                f"{label}: kappa med {s['kappa_rel_err_median']:.3f} corr "
                f"{s['kappa_corr'] if s['kappa_corr'] is not None else float('nan'):.3f} "
                f"lambda med {s['lambda_rel_err_median']:.3f}"
            )
        print(f"{log.split('/')[1]:26s} " + " | ".join(cells))


SECTIONS = {
    "excitation": excitation_section,
    "batch": batch_section,
    "held": held_section,
}


if __name__ == "__main__":
    run_sections(SECTIONS, __doc__)
