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
from vic_drake.reproduce.plots.figure import new_figure

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


#: Rows that a controller may hold constant, the column each plots, and how
#: to say so instead of drawing a flat line.
_MAYBE_FLAT = {
    "stiffness": ("stiffness_z_N_per_m", "K_z fixed at {v:.4g} N/m"),
    "tank": ("tank_energy_J", "tank energy fixed at {v:.4g} J (no energy flow)"),
}


def _varies(df: pd.DataFrame | None, name: str) -> bool:
    """True when the column exists and its finite values are not all one value."""
    if not _has(df, name):
        return False
    v = df[name].to_numpy(float)
    v = v[np.isfinite(v)]
    return bool(np.ptp(v) > 1e-9 * max(1.0, float(np.max(np.abs(v)))))


def _informative(row: str, sim: pd.DataFrame, real: pd.DataFrame | None) -> bool:
    """False for a row that would only draw constant lines (e.g. CS's K_z)."""
    if row not in _MAYBE_FLAT:
        return True
    col = _MAYBE_FLAT[row][0]
    return _varies(sim, col) or _varies(real, col)


def _flat_note(ax, row: str, sim: pd.DataFrame, name: str) -> None:
    """A panel that states the constant instead of drawing a flat line."""
    col, text = _MAYBE_FLAT[row]
    if _has(sim, col):
        v = sim[col].to_numpy(float)
        value = float(v[np.isfinite(v)][0])
        if row == "stiffness" and value == 0.0:
            note = "no stiffness (force control)"
        else:
            note = text.format(v=value)
    else:
        note = f"no {col} in this log"
    ax.set_axis_off()
    ax.text(
        0.5, 0.5, f"{name}: {note}", ha="center", va="center", transform=ax.transAxes
    )


def _rows_with_information(rows, sims, reals) -> tuple:
    """The rows at least one column has information to draw in."""
    return tuple(
        r
        for r in rows
        if any(_informative(r, df, reals.get(name)) for name, df in sims.items())
    )


def _scan_column(
    axes,
    sim: pd.DataFrame,
    real: pd.DataFrame | None,
    title: str,
    rows,
    name: str = "",
):
    t = _col(sim, "t_s")
    for ax, row in zip(axes, rows):
        if not _informative(row, sim, real):
            _flat_note(ax, row, sim, name.upper())
            continue
        if row == "force":
            ax.plot(t, -_col(sim, "force_sensor_z_N"), label="F sim", **_SIM)
            # CS has no force reference (zeros); a cap never below 15 N is off.
            if _has(sim, "force_ref_z_N") and np.any(_col(sim, "force_ref_z_N") != 0):
                ax.plot(
                    t,
                    -_col(sim, "force_ref_z_N"),
                    "--",
                    color="tab:green",
                    lw=1.0,
                    label="F_ref sim",
                )
            f_min = -_col(sim, "force_min_z_N") if _has(sim, "force_min_z_N") else None
            # A bound of 0 is the controller's output before its first tick.
            binding = None if f_min is None else (f_min > 0.0) & (f_min < 14.9)
            if binding is not None and binding.any():
                ax.plot(
                    t,
                    np.where(binding, f_min, np.nan),
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
    if not axes[-1].axison:  # The time axis shows on the last drawn panel.
        drawn = [ax for ax in axes if ax.axison]
        if drawn:
            drawn[-1].set_xlabel("time (s)")
            drawn[-1].xaxis.set_tick_params(labelbottom=True)


def plot_fig6(
    sims: Mapping[str, pd.DataFrame],
    reals: Mapping[str, pd.DataFrame] | None = None,
    *,
    save_path=None,
) -> Figure:
    """Fig. 6: nominal scans (force with F_ref and F_min, K_z, penetration,
    tank), one column per controller. The paper shows VS-CF and VS-VF; any
    of the four controllers may be given.

    Args:
        sims: {controller: df} simulated scans (e.g. "vs-cf", "vs-vf"; >= 1).
        reals: same keys, real logs in the canonical layout (optional).
    """
    if not sims:
        raise VicDrakeError("plot_fig6 needs at least one simulated scan")
    reals = reals or {}
    rows = _rows_with_information(
        ("force", "stiffness", "penetration", "tank"), sims, reals
    )
    fig = new_figure(figsize=(5.0 * len(sims), 2.25 * len(rows)))
    axes = fig.subplots(len(rows), len(sims), sharex="col", squeeze=False)
    for j, (name, sim) in enumerate(sims.items()):
        _scan_column(
            axes[:, j],
            sim,
            reals.get(name),
            f"Fig. 6: {name.upper()} nominal",
            rows,
            name,
        )
    return _finish(fig, save_path)


def _real_disturbed(ax, real: pd.DataFrame | None, name: str) -> None:
    """The paper's own disturbed log on its own time axis: the phantom was
    moved by hand there, not by the simulated lift, so it is not overlaid."""
    if real is None:
        ax.set_axis_off()
        ax.text(
            0.5,
            0.5,
            f"{name.upper()}: no real log",
            ha="center",
            va="center",
            transform=ax.transAxes,
        )
        return
    t = _col(real, "t_s")
    ax.plot(t, -_col(real, "force_sensor_z_N"), label="F real", **_REAL)
    ax.set_ylabel("pressing force (N)")
    ax.set_xlabel("time in the real log (s)")
    ax.set_title(f"the paper's {name.upper()} log: phantom moved by hand", fontsize=9)
    twin = ax.twinx()
    twin.plot(t, 1e3 * _col(real, "z_m"), color="tab:brown", lw=0.8, label="z real")
    twin.set_ylabel("height (mm)")
    lines = ax.get_lines() + twin.get_lines()
    ax.legend(lines, [line.get_label() for line in lines], fontsize=7, loc="best")
    ax.grid(True, alpha=0.3)


def plot_fig7(
    sims: Mapping[str, pd.DataFrame],
    reals: Mapping[str, pd.DataFrame] | None = None,
    *,
    save_path=None,
) -> Figure:
    """Fig. 7: the phantom lifted during the scan (VS-VF, CS, CF): force,
    tip height with the lifted surface, K_z, one column per controller.

    The paper's ``_dist`` logs, when given, get a row of their own below:
    their phantom was moved by hand, differently from the simulated lift
    (``vic-drake compare-real`` replays a log's own motion).

    Args:
        sims: {"vs-vf": df, "cs": df, "cf": df} (any subset, >= 1).
        reals: same keys, real ``_dist`` logs in the canonical layout (optional).
    """
    if not sims:
        raise VicDrakeError("plot_fig7 needs at least one simulated scan")
    reals = {k: v for k, v in (reals or {}).items() if v is not None}
    rows = _rows_with_information(("force", "height", "stiffness"), sims, {})
    n_rows = len(rows) + bool(reals)
    fig = new_figure(figsize=(5.0 * len(sims), 2.35 * n_rows))
    axes = fig.subplots(n_rows, len(sims), squeeze=False)
    for j, (name, sim) in enumerate(sims.items()):
        sim_axes = axes[: len(rows), j]
        for ax in sim_axes[1:]:
            ax.sharex(sim_axes[0])
        _scan_column(
            sim_axes, sim, None, f"Fig. 7: {name.upper()} disturbed", rows, name
        )
        if reals:
            _real_disturbed(axes[-1, j], reals.get(name), name)
    return _finish(fig, save_path)


def plot_comparison(
    sim: pd.DataFrame, real: pd.DataFrame, *, title: str = "", save_path=None
) -> Figure:
    """One experiment, simulated vs real: force, height, K_z (when logged)."""
    rows = ["force", "height"]
    if _has(real, "stiffness_z_N_per_m"):
        rows.append("stiffness")
    fig = new_figure(figsize=(7.0, 2.4 * len(rows)))
    axes = fig.subplots(len(rows), 1, sharex=True, squeeze=False)[:, 0]
    _scan_column(axes, sim, real, title or "simulated vs real", rows)
    return _finish(fig, save_path)


__all__ = ["plot_comparison", "plot_fig6", "plot_fig7"]
