"""The online estimators' settings against the issue's targets on the real logs.

Replays the three palpation logs and the two VS scan logs as
``vic-drake estimate-online`` does (same inputs, same scores) under several
settings of :class:`~vic_drake.estimation.online.OnlineEstimatorParams`, and
prints, per setting and log: convergence_s, the error at the last contact
sample, the median kappa and lambda errors and the kappa correlation.

Sections (``--section``, default all):

- ``settings``: the settings of :data:`SETTINGS` (method, EKF surface walk
  and its prior, EKF kappa/lam walks, RLS memory, covariance reset).
- ``windows``: offline least-squares fits of each palpation log on trailing
  windows (1 and 2 s, one and two cycles) as a ratio to the whole-log fit,
  and from when each stays within 10 % of it: what an estimator of the
  current tissue can reach at best.
- ``trajectory``: on the 1 Hz log, kappa_hat of the RLS, the EKF and the
  EKF with a 1 mm/sqrt(s) surface walk against the trailing 2 s fit.
- ``creep``: per palpation log, the cycle-mean tip height's sink at a
  constant target, as a rate and as a random walk (m / sqrt(s)).
- ``scaled``: the palpation logs with the force scaled by 0.2 ... 4 (kappa
  and lam scaled alike at the same motion: a softer or stiffer phantom
  against the same prior), RLS and EKF with and without the covariance
  reset.

    python benchmarks/online_defaults.py [--section S] [--data-dir DIR]
"""

from __future__ import annotations

import json

import numpy as np
from common import run_sections

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online import OnlineEstimatorParams, run_online
from vic_drake.estimation.palpation import (
    PalpationData,
    estimate_lag,
    fit_hunt_crossley,
    shift,
)
from vic_drake.experiments.online_replay import replay_inputs, score_online
from vic_drake.realdata import read_bag

PALPATIONS = {  # log: palpation period, s
    "palpation/test_soft_1hz": 1.0,
    "palpation/test_soft_2hz": 0.5,
    "palpation/test_soft_25hz": 0.4,
}
SCANS = ("experiments/test_tracking5", "experiments/test_nardi_matForce_lowR")

#: Settings compared (keyword arguments of OnlineEstimatorParams).
SETTINGS = [
    {"method": "rls"},
    {"method": "rls", "clip_reset_s": 0.0},
    {"method": "ekf"},
    {"method": "ekf", "clip_reset_s": 0.0},
    *(
        {"method": "ekf", "surface_walk_m_per_sqrt_s": w}
        for w in (1e-5, 3e-5, 1e-4, 3e-4, 1e-3)
    ),
    *(
        {"method": "ekf", "surface_walk_m_per_sqrt_s": w, "surface_prior_std_m": 2e-4}
        for w in (3e-5, 1e-4, 1e-3)
    ),
    *(
        {"method": "ekf", "kappa_walk_rel_per_sqrt_s": w, "lam_walk_rel_per_sqrt_s": w}
        for w in (0.03, 0.01, 0.003)
    ),
    *({"method": "rls", "memory_s": m} for m in (0.5, 1.0, 4.0)),
]


def _replay(inputs_cache, data_dir, log, params, scale=1.0):
    if log not in inputs_cache:
        inputs_cache[log] = replay_inputs(data_dir / log, params)
    kind, (t, z, vz, f, s), k_ref, l_ref, lag = inputs_cache[log]
    trace = run_online(t, z, vz, f * scale, s, params)
    return score_online(kind, trace, k_ref * scale, l_ref * scale, lag, params)


def _line(result) -> str:
    s = result.summary
    return (
        f"conv {s['convergence_s']:6.2f} s  final {result.final_kappa_rel_err:.3f}  "
        f"kappa med {s['kappa_rel_err_median']:.3f}  corr {s['kappa_corr']:5.2f}  "
        f"lambda med {s['lambda_rel_err_median']:.3f}"
    )


def settings_section(data_dir) -> None:
    cache = {}
    for kwargs in SETTINGS:
        print(json.dumps(kwargs))
        for log in (*PALPATIONS, *SCANS):
            result = _replay(cache, data_dir, log, OnlineEstimatorParams(**kwargs))
            print(f"  {log.split('/')[1]:26s} {_line(result)}")


def _aligned(data_dir, log):
    data = PalpationData.from_frame(read_bag(data_dir / log))
    aligned = shift(data, estimate_lag(data))
    return aligned, fit_hunt_crossley(aligned)


def windows_section(data_dir) -> None:
    for log, period in PALPATIONS.items():
        data, whole = _aligned(data_dir, log)
        t = data.t_s - data.t_s[0]
        touching = (data.force_N > 0.5) & (data.penetration_m > 0.5e-3)
        t0 = t[np.flatnonzero(touching)[0]]
        print(f"{log}: whole-log kappa {whole.kappa:.0f}, first contact {t0:.2f} s")
        for width in sorted({period, 2 * period, 1.0, 2.0}):
            ends = np.arange(t0 + width, min(t[-1], t0 + 12.0), 0.25)
            ratios = []
            for end in ends:
                try:
                    fit = fit_hunt_crossley(
                        data, sample_mask=(t >= end - width) & (t < end)
                    )
                    ratios.append(fit.kappa / whole.kappa)
                except VicDrakeError:  # too few samples in contact
                    ratios.append(np.nan)
            ratios = np.array(ratios)
            ok = np.isfinite(ratios)  # windows without contact do not count
            out = np.abs(ratios[ok] - 1.0) > 0.1
            kept = ends[ok]
            if out[-1]:
                since = np.nan
            else:
                since = kept[np.flatnonzero(out)[-1] + 1] if out.any() else kept[0]
            shown = " ".join(
                f"{e - t0:.1f}:{r:.3f}" for e, r in list(zip(ends, ratios))[::4]
            )
            print(
                f"  trailing {width:.1f} s: within 10 % from {since - t0:.2f} s after "
                f"contact; t:ratio {shown}"
            )


#: Stretches at a constant excitation (the 1 Hz log's indentation deepens by
#: 3 mm at 7 s, its force range goes from 3.3-5.5 N to 4.4-8.7 N), s.
CREEP_SPANS = {
    "palpation/test_soft_1hz": ((2.0, 7.0), (8.0, None)),
    "palpation/test_soft_2hz": ((2.0, None),),
    "palpation/test_soft_25hz": ((2.0, None),),
}


def trajectory_section(data_dir, log="palpation/test_soft_1hz") -> None:
    """kappa_hat / whole-log fit against the trailing 2 s fit, after first contact."""
    data, whole = _aligned(data_dir, log)
    t = data.t_s - data.t_s[0]
    runs = {
        "rls": {"method": "rls"},
        "ekf": {"method": "ekf"},
        "ekf walk 1e-3": {"method": "ekf", "surface_walk_m_per_sqrt_s": 1e-3},
    }
    cache, traces = {}, {}
    for name, kwargs in runs.items():
        trace = _replay(cache, data_dir, log, OnlineEstimatorParams(**kwargs)).trace
        traces[name] = (trace, trace.t_s[np.flatnonzero(trace.in_contact)[0]])
    print(f"{log}: ratios to the whole-log kappa {whole.kappa:.0f}")
    print("  t after contact | trailing 2 s fit | " + " | ".join(runs))
    t0 = traces["rls"][1] - data.t_s[0]
    for after in (
        0.5,
        1.0,
        1.5,
        2.0,
        2.5,
        3.0,
        3.5,
        4.0,
        6.0,
        8.0,
        10.0,
        20.0,
        40.0,
        60.0,
    ):
        end = t0 + after
        try:
            window = (t >= end - 2.0) & (t < end)
            fit = (
                f"{fit_hunt_crossley(data, sample_mask=window).kappa / whole.kappa:.3f}"
            )
        except VicDrakeError:  # too few samples in contact
            fit = "  -  "
        cells = []
        for trace, first in traces.values():
            k = min(np.searchsorted(trace.t_s, first + after), trace.t_s.size - 1)
            cells.append(f"{trace.kappa[k] / whole.kappa:.3f}")
        print(f"  {after:5.1f} s | {fit} | " + " | ".join(cells))


def creep_section(data_dir) -> None:
    for log, period in PALPATIONS.items():
        data = PalpationData.from_frame(read_bag(data_dir / log))
        t = data.t_s - data.t_s[0]
        for a, b in CREEP_SPANS[log]:
            _creep_line(log, data, t, period, a, t[-1] if b is None else b)


def _creep_line(log, data, t, period, a, b) -> None:
    starts = np.arange(a, b - period + 1e-9, period)
    cycles = [(t >= c) & (t < c + period) for c in starts]
    z = np.array([data.z_m[m].mean() for m in cycles])
    f = np.array([data.force_N[m].mean() for m in cycles])
    dz, span = z[-1] - z[0], starts[-1] - starts[0]
    print(
        f"{log} [{a:.0f}, {b:.0f}) s: cycle-mean z {dz * 1e3:+.3f} mm over {span:.1f} s "
        f"({dz / span * 1e6:+.1f} um/s; as a random walk {abs(dz) / np.sqrt(span):.1e} "
        f"m/sqrt(s)); cycle-mean force {f[-1] / f[0] - 1:+.1%}"
    )


def scaled_section(data_dir) -> None:
    scales = (0.2, 0.3, 0.5, 1.0, 2.0, 4.0)
    for kwargs in (
        {"method": "rls"},
        {"method": "rls", "clip_reset_s": 0.0},
        {"method": "ekf"},
        {"method": "ekf", "clip_reset_s": 0.0},
    ):
        params = OnlineEstimatorParams(**kwargs)
        cache = {}
        for log in PALPATIONS:
            cells = []
            for scale in scales:
                s = _replay(cache, data_dir, log, params, scale).summary
                cells.append(
                    f"x{scale:g} {s['convergence_s']:.2f} s "
                    f"{s['kappa_rel_err_median']:.3f}/{s['lambda_rel_err_median']:.3f}"
                )
            label = ", ".join(f"{k} {v}" for k, v in kwargs.items())
            print(f"{label:34s} {log.split('/')[1]:15s} " + " | ".join(cells))
    print("(cells: convergence, kappa / lambda median errors)")


SECTIONS = {
    "settings": settings_section,
    "windows": windows_section,
    "trajectory": trajectory_section,
    "creep": creep_section,
    "scaled": scaled_section,
}


if __name__ == "__main__":
    run_sections(SECTIONS, __doc__)
