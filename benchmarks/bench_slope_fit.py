"""The slope fit's tick cost and outputs: this checkout against another.

Runs the surface-from-slope EKF (``ekf_slope_step``) and the slope fit
alone (``slope_step``) of this checkout and of ``--baseline DIR`` (another
checkout, e.g. ``git worktree add DIR <commit>``) in one process,
interleaved sample by sample (which of the two goes first alternates), so
that both see the same machine load, over

- a synthetic press 6 mm deep into a surface rising at 1 mm/s, the
  penetration dithered 0.3 mm at 3 Hz, 0.045 N of noise (20 s);
- the palpation logs and the variable-impedance scan logs of the data
  folder as ``vic-drake estimate-online`` feeds them, but with the surface
  unknown (NaN), so that the EKF runs on the slope fit's surface.

Prints per log and function the median and p99 wall time of a tick (best
of three runs for each percentile; ``--cpu``: the thread's CPU time) and the largest relative difference of
every output between the two checkouts (over samples where both are
finite; a differing NaN pattern is reported). The issue's budget is 30 us
p99 per tick.

Each checkout's fit is told the dither's frequency, 3 Hz
(``--dither-hz``; 0: not told), where its functions take it, so that a
checkout with the dither as the fit's instrument
(``slope_instrument``) times that path on every log (the logs' outputs
then differ from a checkout without it, as they should).

    python benchmarks/bench_slope_fit.py --baseline DIR
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import math
import sys
import time

import numpy as np
from common import HERE, is_checkout, versions

_LOGS = (
    "palpation/test_soft_1hz",
    "palpation/test_soft_2hz",
    "palpation/test_soft_25hz",
    "experiments/test_nardi_matForce_lowR",
    "experiments/test_tracking5",
)


def _load(tree: str):
    """(ekf module, slope module, params class) of the vic_drake in ``tree``."""

    def ours(name):
        return name == "vic_drake" or name.startswith("vic_drake.")

    saved = {k: v for k, v in sys.modules.items() if ours(k)}
    for k in saved:
        del sys.modules[k]
    sys.path.insert(0, tree)
    try:
        ekf = importlib.import_module("vic_drake.estimation.online.ekf")
        slope = importlib.import_module("vic_drake.estimation.online.slope")
        params = importlib.import_module("vic_drake.estimation.online.params")
    finally:
        sys.path.remove(tree)
        for k in [k for k in sys.modules if ours(k)]:
            del sys.modules[k]
        sys.modules.update(saved)
    return ekf, slope, params.OnlineEstimatorParams


def dithered_press(duration_s=20.0):
    """(t, z, z_dot, force) of the synthetic press of the module docstring."""
    rng = np.random.default_rng(0)
    t = np.arange(0.0, duration_s, 0.002)
    w = 2.0 * np.pi * 3.0
    eps = 0.006 + 3e-4 * np.sin(w * t)
    eps_dot = 3e-4 * w * np.cos(w * t)
    force = (6000.0 + 40000.0 * eps_dot) * eps**1.35 + rng.normal(0.0, 0.045, t.size)
    return t, 0.1 + 0.001 * t - eps, 0.001 - eps_dot, force


def _inputs():
    """{log name: (t, z, z_dot, force)}."""
    logs = {"synthetic dithered press": dithered_press()}
    from vic_drake.estimation.online import OnlineEstimatorParams
    from vic_drake.experiments.online_replay import replay_inputs
    from vic_drake.paths import has_data, resolve_data_dir

    if has_data():
        for name in _LOGS:
            _, (t, z, v, f, _), *_ = replay_inputs(
                resolve_data_dir() / name, OnlineEstimatorParams(method="ekf")
            )
            logs[name] = (t, z, v, f)
    return logs


def _step(modules, what: str, dither_hz: float):
    """(step(state, row) -> (state, outputs), initial state) of one checkout
    (told ``dither_hz`` where its step takes it)."""
    ekf, slope, params_cls = modules
    p = params_cls(method="ekf", surface_from_slope=True, surface_walk_m_per_sqrt_s=0.0)
    step = ekf.ekf_slope_step if what == "ekf_slope_step" else slope.slope_step
    extra = (
        {"dither_hz": dither_hz}
        if "dither_hz" in inspect.signature(step).parameters
        else {}
    )
    if what == "ekf_slope_step":
        return (
            lambda s, row: step(s, *row, math.nan, p, **extra)
        ), ekf.ekf_slope_initial_state(p)
    return (lambda s, row: step(s, *row, p, **extra)), slope.slope_initial_state()


def _run(pair, rows, clock=time.perf_counter):
    """Per-tick times (2, n), us, and outputs (2, n, k) of the two steps."""
    (step_a, state_a), (step_b, state_b) = pair
    n = len(rows)
    ticks = np.empty((2, n))
    out_a, out_b = [], []
    for k, row in enumerate(rows):
        if k % 2:
            t0 = clock()
            state_a, ea = step_a(state_a, row)
            t1 = clock()
            state_b, eb = step_b(state_b, row)
            t2 = clock()
            ticks[0, k], ticks[1, k] = t1 - t0, t2 - t1
        else:
            t0 = clock()
            state_b, eb = step_b(state_b, row)
            t1 = clock()
            state_a, ea = step_a(state_a, row)
            t2 = clock()
            ticks[0, k], ticks[1, k] = t2 - t1, t1 - t0
        out_a.append(ea)
        out_b.append(eb)
    return ticks * 1e6, np.array(out_a, float), np.array(out_b, float)


def _differences(a, b, fields) -> str:
    parts = []
    for i, name in enumerate(fields):
        x, y = a[:, i], b[:, i]
        if not np.array_equal(np.isnan(x), np.isnan(y)):
            parts.append(f"{name} NaN pattern differs")
            continue
        ok = np.isfinite(x) & np.isfinite(y)
        scale = np.maximum(np.abs(x[ok]), np.abs(y[ok]))
        diff = np.abs(x[ok] - y[ok])
        rel = np.max(np.where(diff > 0.0, diff / np.maximum(scale, 1e-300), 0.0))
        parts.append(f"{name} {rel:.1e}" if ok.any() else f"{name} -")
    return ", ".join(parts)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="DIR", required=True)
    parser.add_argument("--runs", type=int, default=3, help="runs per log (best of)")
    parser.add_argument(
        "--dither-hz",
        type=float,
        default=3.0,
        metavar="HZ",
        help="the dither frequency the fits are told, Hz (0: not told; default 3.0)",
    )
    parser.add_argument(
        "--cpu",
        action="store_true",
        help="time ticks with this thread's CPU time instead of the wall clock "
        "(leaves out the time the process waits for a core on a loaded machine; "
        "each reading costs about a microsecond)",
    )
    args = parser.parse_args()
    if not is_checkout(args.baseline):
        parser.error(f"--baseline {args.baseline!r} holds no vic_drake package")
    if args.runs < 1:
        parser.error(f"--runs must be >= 1; got {args.runs}")
    if not (math.isfinite(args.dither_hz) and args.dither_hz >= 0.0):
        parser.error(f"--dither-hz must be >= 0; got {args.dither_hz}")
    print(versions())
    print(f"this checkout {HERE} against the baseline {args.baseline}")
    print("tick times: " + ("thread CPU time" if args.cpu else "wall clock"))
    print(f"the fits are told a dither at {args.dither_hz} Hz where they take it")
    new = _load(HERE)
    old = _load(args.baseline)
    from vic_drake.estimation.online.core import OUTPUT_FIELDS

    slope_fields = old[1].SlopeEstimate._fields
    for log, (t, z, v, f) in _inputs().items():
        rows = list(zip(t.tolist(), z.tolist(), v.tolist(), f.tolist()))
        for what in ("ekf_slope_step", "slope_step"):
            pair = [_step(modules, what, args.dither_hz) for modules in (old, new)]
            clock = time.thread_time if args.cpu else time.perf_counter
            results = [_run(pair, rows, clock) for _ in range(args.runs)]
            p50 = np.min([np.median(r[0], axis=1) for r in results], axis=0)
            p99 = np.min([np.percentile(r[0], 99, axis=1) for r in results], axis=0)
            fields = OUTPUT_FIELDS if what == "ekf_slope_step" else slope_fields
            print(
                f"{log:<38} {what:<15} baseline median {p50[0]:6.1f} p99 {p99[0]:6.1f} us"
                f" | this median {p50[1]:6.1f} p99 {p99[1]:6.1f} us"
            )
            _, a, b = results[0]
            print(f"{'':<38} largest relative difference: {_differences(a, b, fields)}")
            if what == "slope_step":  # The solves that count (both valid).
                both = (a[:, -1] == 1.0) & (b[:, -1] == 1.0)
                print(
                    f"{'':<38} ... where both are valid ({both.sum()} samples): "
                    + _differences(a[both], b[both], fields[:-1])
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
