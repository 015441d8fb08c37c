"""Figures of the offline phase: Table I, Fig. 2 (load test), Fig. 3
(residual vs palpation time), the beta sweep and the sensor-lag search.

Every function takes results of :mod:`vic_drake.estimation` and returns a
matplotlib Figure; the only I/O is the optional ``save_path``.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from vic_drake.estimation.loadtest import LoadTestResult
from vic_drake.estimation.palpation import (
    PAPER_TABLE_I,
    BetaSweep,
    LagProfile,
    ModelComparison,
    ResidualCurve,
)
from vic_drake.reproduce.plots.figure import new_figure


def _finish(fig: Figure, save_path) -> Figure:
    fig.tight_layout()
    if save_path is not None:
        fig.savefig(save_path, dpi=150)
    return fig


def _as_mapping(value, default_name: str) -> dict:
    if isinstance(value, Mapping):
        return dict(value)
    return {default_name: value}


def _table_rows(comparison: ModelComparison) -> list[tuple[str, float]]:
    rows = [("Kelvin-Voigt", comparison.kelvin_voigt.relative)]
    for beta, fit in comparison.hunt_crossley.items():
        rows.append((f"HC β={beta:g}", fit.relative))
    return rows


def plot_table_i(
    comparisons: ModelComparison | Mapping[str, ModelComparison],
    *,
    paper: Mapping | None = PAPER_TABLE_I,
    title: str | None = "Table I: relative residual per model",
    save_path=None,
) -> Figure:
    """Grouped bars of the relative residual of KV and HC at each beta.

    Args:
        comparisons: one ModelComparison or {log name: ModelComparison}.
        paper: the paper's Table I values (drawn as black markers), or None.
    """
    comparisons = _as_mapping(comparisons, "log")
    names = list(comparisons)
    labels = [label for label, _ in _table_rows(comparisons[names[0]])]
    fig = new_figure(figsize=(7.0, 4.0))
    ax = fig.add_subplot()
    x = np.arange(len(labels))
    width = 0.8 / max(len(names), 1)
    for i, name in enumerate(names):
        values = [v for _, v in _table_rows(comparisons[name])]
        ax.bar(x + (i - (len(names) - 1) / 2) * width, values, width, label=name)
    if paper is not None:
        first = comparisons[names[0]]
        keys = ["kelvin_voigt", *first.hunt_crossley]
        values = [paper.get(k, np.nan) for k in keys]
        ax.plot(x, values, "k_", markersize=24, markeredgewidth=2.5, label="paper")
    ax.set_xticks(x, labels)
    ax.set_ylabel("relative residual (RMS residual / RMS force)")
    if title:
        ax.set_title(title)
    ax.legend(fontsize="small")
    ax.grid(axis="y", alpha=0.3)
    return _finish(fig, save_path)


def plot_beta_sweep(
    sweeps: BetaSweep | Mapping[str, BetaSweep],
    *,
    title: str | None = "Hunt-Crossley residual against β",
    save_path=None,
) -> Figure:
    """Relative residual against beta, best beta marked, one curve per log."""
    sweeps = _as_mapping(sweeps, "log")
    fig = new_figure(figsize=(6.0, 4.0))
    ax = fig.add_subplot()
    for name, sweep in sweeps.items():
        (line,) = ax.plot(sweep.betas, sweep.relative, "-o", markersize=3, label=name)
        ax.axvline(sweep.best_beta, color=line.get_color(), linestyle=":", alpha=0.8)
    ax.axvline(1.35, color="k", linestyle="--", alpha=0.5, label="paper β = 1.35")
    ax.set_xlabel("β")
    ax.set_ylabel("relative residual")
    if title:
        ax.set_title(title)
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return _finish(fig, save_path)


def plot_load_test(
    result: LoadTestResult, *, title: str | None = None, save_path=None
) -> Figure:
    """Fig. 2: measured load-test force against the KV and HC predictions."""
    fig = new_figure(figsize=(7.0, 4.5))
    ax = fig.add_subplot()
    ax.plot(result.t_s, result.measured_N, color="0.3", lw=1.0, label="measured")
    ax.plot(
        result.t_s,
        result.kelvin_voigt_N,
        lw=1.5,
        label=f"Kelvin-Voigt (RMS {result.kelvin_voigt_rms_N:.2f} N)",
    )
    ax.plot(
        result.t_s,
        result.hunt_crossley_N,
        lw=1.5,
        label=f"Hunt-Crossley β={result.beta:g} (RMS {result.hunt_crossley_rms_N:.2f} N)",
    )
    ax.set_xlabel("time [s]")
    ax.set_ylabel("force on the probe [N]")
    ax.set_title(title or "Load/unload test")
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    if result.penetration_m is not None:
        ax2 = ax.twinx()
        ax2.plot(result.t_s, 1e3 * result.penetration_m, color="C7", ls=":", lw=1.0)
        ax2.set_ylabel("penetration [mm] (dotted)")
    return _finish(fig, save_path)


def plot_residual_vs_time(
    curves: ResidualCurve | Mapping[str, ResidualCurve],
    *,
    title: str | None = "Residual against palpation time",
    save_path=None,
) -> Figure:
    """Fig. 3: whole-log relative residual of window fits, with the
    exponential fit a exp(-t/tau) + c."""
    curves = _as_mapping(curves, "log")
    fig = new_figure(figsize=(6.0, 4.0))
    ax = fig.add_subplot()
    for name, curve in curves.items():
        (line,) = ax.plot(curve.window_s, curve.relative, "o", markersize=3, label=name)
        if curve.exp_fit is not None:
            t = np.linspace(curve.window_s[0], curve.window_s[-1], 300)
            f = curve.exp_fit
            ax.plot(
                t,
                f(t),
                color=line.get_color(),
                label=f"{f.a:.3g}·exp(-t/{f.tau_s:.3g} s) + {f.c:.3g}",
            )
    ax.axvline(5.0, color="k", ls="--", alpha=0.4, label="paper's 5 s")
    ax.set_xlabel("palpation time [s]")
    ax.set_ylabel("relative residual on the whole palpation")
    if title:
        ax.set_title(title)
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return _finish(fig, save_path)


def plot_lag_profile(
    profiles: LagProfile | Mapping[str, LagProfile],
    *,
    title: str | None = "Sensor-lag search (reference HC fit)",
    save_path=None,
) -> Figure:
    """RMS residual (relative to each log's minimum) against candidate lag."""
    profiles = _as_mapping(profiles, "log")
    fig = new_figure(figsize=(6.0, 4.0))
    ax = fig.add_subplot()
    for name, prof in profiles.items():
        (line,) = ax.plot(1e3 * prof.lags_s, prof.rms_N / prof.rms_N.min(), label=name)
        ax.axvline(1e3 * prof.lag_s, color=line.get_color(), ls=":")
    ax.axvline(56.0, color="k", ls="--", alpha=0.4, label="real controller: 28 ticks")
    ax.set_xlabel("lag of force behind position [ms]")
    ax.set_ylabel("RMS residual / minimum")
    if title:
        ax.set_title(title)
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return _finish(fig, save_path)


def plot_palpation_summary(
    comparison: ModelComparison, *, title: str | None = None, save_path=None
) -> Figure:
    """Table I bars and, if the comparison holds one, the beta sweep."""
    fig = new_figure(figsize=(11.0, 4.0))
    ax1, ax2 = fig.subplots(1, 2)
    rows = _table_rows(comparison)
    ax1.bar([r[0] for r in rows], [r[1] for r in rows], color="C0")
    ax1.set_ylabel("relative residual")
    ax1.set_title(f"lag {comparison.lag_s * 1e3:.1f} ms")
    ax1.grid(axis="y", alpha=0.3)
    if comparison.sweep is not None:
        s = comparison.sweep
        ax2.plot(s.betas, s.relative, "-o", markersize=3)
        ax2.axvline(
            s.best_beta, ls=":", color="C1", label=f"best β = {s.best_beta:.3f}"
        )
        ax2.set_xlabel("β")
        ax2.set_ylabel("relative residual")
        ax2.legend(fontsize="small")
        ax2.grid(alpha=0.3)
    else:
        ax2.set_visible(False)
    if title:
        fig.suptitle(title)
    return _finish(fig, save_path)
