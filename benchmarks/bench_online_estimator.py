"""Cost of one online-estimator tick as a function (RLS, EKF variants).

Prints the median and p99 wall time of ``rls_step`` / ``ekf_step`` (and
``ekf_slope_step``) over a simulated 1.5 Hz Hunt-Crossley palpation (20 s
at 500 Hz) and over the shared palpation log if the data folder is
present. The issue's budget is 30 us p99 per tick. Run:
``python benchmarks/bench_online_estimator.py``.
"""

import numpy as np
from common import versions

from vic_drake.estimation.online import OnlineEstimatorParams, run_online
from vic_drake.paths import has_data, resolve_data_dir

VARIANTS = {
    "rls": OnlineEstimatorParams(method="rls"),
    "ekf (kappa, lam)": OnlineEstimatorParams(method="ekf"),
    "ekf (+ surface)": OnlineEstimatorParams(
        method="ekf", surface_walk_m_per_sqrt_s=1e-3
    ),
    "ekf (+ surface, beta)": OnlineEstimatorParams(
        method="ekf", surface_walk_m_per_sqrt_s=1e-3, estimate_beta=True
    ),
    # The slope fit runs every tick (its surface is not used: the log's is
    # given; benchmarks/bench_slope_fit.py runs it on an unknown surface).
    "ekf (+ slope fit)": OnlineEstimatorParams(method="ekf", surface_from_slope=True),
}


def simulated(duration_s=20.0):
    rng = np.random.default_rng(0)
    t = np.arange(0.0, duration_s, 0.002)
    eps = 0.006 - 0.003 * np.cos(2 * np.pi * 1.5 * t)
    eps_dot = 0.003 * 2 * np.pi * 1.5 * np.sin(2 * np.pi * 1.5 * t)
    force = (4000 + 30000 * eps_dot) * eps**1.35 + rng.normal(0, 0.05, t.size)
    return t, 0.1 - eps, -eps_dot, force, 0.1


def main():
    print(versions())
    logs = {"simulated 1.5 Hz": simulated()}
    if has_data():
        from vic_drake.estimation.palpation import PalpationData
        from vic_drake.realdata import read_bag

        df = read_bag(resolve_data_dir() / "palpation" / "test_soft_2hz")
        d = PalpationData.from_frame(df)
        logs["palpation/test_soft_2hz"] = (
            d.t_s,
            d.z_m,
            df["vz_m_per_s"].to_numpy()[: d.n],
            d.force_N,
            d.surface_z_m,
        )
    for log, args in logs.items():
        for name, params in VARIANTS.items():
            ticks = []
            for _ in range(3):  # Best of three runs per percentile (machine load).
                ticks.append(run_online(*args, params).tick_s * 1e6)
            med = min(np.median(x) for x in ticks)
            p99 = min(np.percentile(x, 99) for x in ticks)
            print(f"{log:<26} {name:<24} median {med:5.1f} us   p99 {p99:5.1f} us")


if __name__ == "__main__":
    main()
