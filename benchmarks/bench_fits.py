"""Timing of the offline fits (prints figures; no asserts).

    /work/venv/bin/python benchmarks/bench_fits.py [--data-dir DIR]

Reports the time of one Hunt-Crossley fit on a 5 s simulated palpation (the
palpation campaign calls it once per palpation point), of the lag search,
and of the whole ``fit-palpation`` / ``load-test`` pipelines on the real
logs when they are present.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from common import versions

from vic_drake.estimation import (
    PalpationData,
    compare_models,
    fit_hunt_crossley,
    lag_profile,
    load_test,
    residual_vs_palpation_time,
    shift,
)
from vic_drake.paths import has_data, resolve_data_dir
from vic_drake.tissue import hunt_crossley_force


def best_of(fn, repeat=5):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def synthetic(duration_s=5.0):
    t = 0.002 * np.arange(int(duration_s / 0.002))
    w = 2 * np.pi * 1.0
    eps = 0.008 + 0.002 * np.sin(w * t)
    force = hunt_crossley_force(eps, 0.002 * w * np.cos(w * t), 4000.0, 20000.0, 1.35)
    return PalpationData(t_s=t, z_m=-0.05 - eps, force_N=force, surface_z_m=-0.05)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data-dir", default=None)
    args = parser.parse_args()
    print(versions())

    data = synthetic()
    print(
        f"fit_hunt_crossley, 5 s at 500 Hz ({data.n} samples): "
        f"{1e3 * best_of(lambda: fit_hunt_crossley(data, 1.35)):.2f} ms"
    )
    print(
        f"lag_profile over [0, 0.2] s, same data: "
        f"{1e3 * best_of(lambda: lag_profile(data), 3):.1f} ms"
    )

    data_dir = resolve_data_dir(args.data_dir)
    if not has_data(data_dir):
        print(f"(no real data at {data_dir}; skipping the real logs)")
        return
    from vic_drake.realdata import read_bag

    logs = {}
    for name in ("test_soft_1hz", "test_soft_2hz", "test_soft_25hz"):
        t0 = time.perf_counter()
        logs[name] = PalpationData.from_frame(read_bag(data_dir / "palpation" / name))
        read_s = time.perf_counter() - t0
        d = logs[name]
        fit_s = best_of(lambda d=d: compare_models(d), 2)
        c = compare_models(d)
        curve_s = best_of(
            lambda d=d, c=c: residual_vs_palpation_time(shift(d, c.lag_s)), 2
        )
        print(
            f"{name}: {d.n} samples, read {read_s:.2f} s, lag+KV+HC+sweep "
            f"{fit_s:.2f} s, residual-vs-time {curve_s:.2f} s"
        )
    load = PalpationData.from_frame(read_bag(data_dir / "loadcycle" / "test_soft_1"))
    print(
        f"load_test (fit on test_soft_1hz): "
        f"{best_of(lambda: load_test(load, logs['test_soft_1hz']), 2):.2f} s"
    )


if __name__ == "__main__":
    main()
