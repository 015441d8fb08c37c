"""Figures of the scans: the paper's Fig. 6 (nominal VS-CF and VS-VF) and
Fig. 7 (disturbance: VS-VF, CS, CF), simulated with the real log overlaid
where one exists.

Every function takes canonical scan DataFrames (``run_scan(...).df`` or
``metrics.real_to_canonical(read_bag(...))``) and returns a matplotlib
Figure; the only I/O is the optional ``save_path``. Forces are drawn as
pressing forces (positive = into the body), as in the paper's figures.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from vic_drake.errors import VicDrakeError

_SIM = {"color": "tab:blue", "lw": 1.2}
_REAL = {"color": "0.35", "lw": 1.0, "alpha": 0.8}


def _finish(fig: Figure, save_path) -> Figure:
    fig.tight_layout()
    if save_path is not None:
        fig.savefig(save_path, dpi=150)
    return fig


def _col(df: pd.DataFrame, name: str) -> np.ndarray:
    if name not in df.columns:
        raise VicDrakeError(
            f"scan DataFrame lacks column {name!r}; expected the canonical layout"
        )
    return df[name].to_numpy(float)


def _has(df: pd.DataFrame | None, name: str) -> bool:
    return (
        df is not None
        and name in df.columns
        and np.isfinite(df[name].to_numpy(float)).any()
    )


def _scan_column(axes, sim: pd.DataFrame, real: pd.DataFrame | None, title: str, rows):
    t = _col(sim, "t_s")
    for ax, row in zip(axes, rows):
        if row == "force":
            ax.plot(t, -_col(sim, "force_sensor_z_N"), label="F sim", **_SIM)
            if _has(sim, "force_ref_z_N"):
                ax.plot(
                    t,
                    -_col(sim, "force_ref_z_N"),
                    "--",
                    color="tab:green",
                    lw=1.0,
                    label="F_ref sim",
                )
            if _has(sim, "force_min_z_N"):
                f_min = -_col(sim, "force_min_z_N")
                ax.plot(
                    t,
                    np.where(f_min < 14.9, f_min, np.nan),
                    ":",
                    color="tab:red",
                    lw=1.0,
                    label="-F_min sim",
                )
            if real is not None:
                ax.plot(
                    _col(real, "t_s"),
                    -_col(real, "force_sensor_z_N"),
                    label="F real",
                    **_REAL,
                )
            ax.set_ylabel("pressing force (N)")
        elif row == "stiffness":
            ax.plot(t, _col(sim, "stiffness_z_N_per_m"), label="K_z sim", **_SIM)
            if _has(real, "stiffness_z_N_per_m"):
                ax.plot(
                    _col(real, "t_s"),
                    _col(real, "stiffness_z_N_per_m"),
                    label="K_z real",
                    **_REAL,
                )
            ax.set_ylabel("K_z (N/m)")
        elif row == "penetration":
            ax.plot(t, 1e3 * _col(sim, "penetration_m"), label="ε sim", **_SIM)
            if _has(real, "penetration_m"):
                ax.plot(
                    _col(real, "t_s"),
                    1e3 * _col(real, "penetration_m"),
                    label="ε real",
                    **_REAL,
                )
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_ylabel("penetration (mm)")
        elif row == "tank":
            ax.plot(t, _col(sim, "tank_energy_J"), label="T sim", **_SIM)
            if _has(real, "tank_energy_J"):
                ax.plot(
                    _col(real, "t_s"),
                    _col(real, "tank_energy_J"),
                    label="T real",
                    **_REAL,
                )
            ax.set_ylabel("tank (J)")
        elif row == "height":
            ax.plot(t, 1e3 * _col(sim, "z_m"), label="z sim", **_SIM)
            if _has(sim, "phantom_lift_m"):
                ax.plot(
                    t,
                    1e3 * (_col(sim, "surface_z_m")),
                    "--",
                    color="tab:orange",
                    lw=1.0,
                    label="surface sim",
                )
            if real is not None:
                ax.plot(
                    _col(real, "t_s"), 1e3 * _col(real, "z_m"), label="z real", **_REAL
                )
            ax.set_ylabel("height (mm)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    axes[0].set_title(title)
    axes[-1].set_xlabel("time (s)")


def plot_fig6(
    sims: Mapping[str, pd.DataFrame],
    reals: Mapping[str, pd.DataFrame] | None = None,
    *,
    save_path=None,
) -> Figure:
    """Fig. 6: nominal VS-CF and VS-VF (force with F_ref and F_min, K_z,
    penetration, tank), one column per controller.

    Args:
        sims: {"vs-cf": df, "vs-vf": df} simulated scans (any subset, >= 1).
        reals: same keys, real logs in the canonical layout (optional).
    """
    if not sims:
        raise VicDrakeError("plot_fig6 needs at least one simulated scan")
    reals = reals or {}
    rows = ("force", "stiffness", "penetration", "tank")
    fig = Figure(figsize=(5.0 * len(sims), 9.0))
    axes = fig.subplots(len(rows), len(sims), sharex="col", squeeze=False)
    for j, (name, sim) in enumerate(sims.items()):
        _scan_column(
            axes[:, j], sim, reals.get(name), f"Fig. 6: {name.upper()} nominal", rows
        )
    return _finish(fig, save_path)


def plot_fig7(
    sims: Mapping[str, pd.DataFrame],
    reals: Mapping[str, pd.DataFrame] | None = None,
    *,
    save_path=None,
) -> Figure:
    """Fig. 7: the phantom lifted during the scan (VS-VF, CS, CF): force,
    tip height with the lifted surface, K_z, one column per controller.

    Args:
        sims: {"vs-vf": df, "cs": df, "cf": df} (any subset, >= 1).
        reals: same keys, real ``_dist`` logs in the canonical layout (optional).
    """
    if not sims:
        raise VicDrakeError("plot_fig7 needs at least one simulated scan")
    reals = reals or {}
    rows = ("force", "height", "stiffness")
    fig = Figure(figsize=(5.0 * len(sims), 7.0))
    axes = fig.subplots(len(rows), len(sims), sharex="col", squeeze=False)
    for j, (name, sim) in enumerate(sims.items()):
        _scan_column(
            axes[:, j], sim, reals.get(name), f"Fig. 7: {name.upper()} disturbed", rows
        )
    return _finish(fig, save_path)


def plot_comparison(
    sim: pd.DataFrame, real: pd.DataFrame, *, title: str = "", save_path=None
) -> Figure:
    """One experiment, simulated vs real: force, height, K_z (when logged)."""
    rows = ["force", "height"]
    if _has(real, "stiffness_z_N_per_m"):
        rows.append("stiffness")
    fig = Figure(figsize=(7.0, 2.4 * len(rows)))
    axes = fig.subplots(len(rows), 1, sharex=True, squeeze=False)[:, 0]
    _scan_column(axes, sim, real, title or "simulated vs real", rows)
    return _finish(fig, save_path)


__all__ = ["plot_comparison", "plot_fig6", "plot_fig7"]
