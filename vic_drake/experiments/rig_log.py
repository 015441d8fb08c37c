"""A simulated scan's log as the real rig wrote it, and as a ROS 2 bag.

The scan diagram logs, beside the canonical signals
(:mod:`vic_drake.experiments.scan_logs`), the signals only a rig log holds
(:data:`vic_drake.analysis.rig_layout.RIG_SIGNALS`): the position,
velocity and force the controller read, its map sample, its map-based
penetration and surface-velocity estimate (the controller's record of each
tick). :func:`rig_log_rows` turns a :class:`~vic_drake.experiments.scan_run.ScanResult` into the rig's
rows: the 31-column ``/adaptive_stiffness_data`` layout for the VS
controllers, the 9-column ``/data_control`` layout for CS and CF, as on the
rig; :func:`write_scan_bag` writes them as a ROS 2 bag.
:func:`write_palpation_bag` writes a simulated palpation in the rig's
palpation layout.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from vic_drake.analysis.rig_layout import (
    RIG_SIGNALS,
    controller_log_rows,
    scan_log_rows,
)
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import PALPATION_COLUMNS
from vic_drake.realdata_write import write_bag
from vic_drake.systems.signals import CONTACT_FIELDS, TICK_RECORD_FIELDS


class RigGroup(NamedTuple):
    """One logged port and the rig signals its elements fill (None: not kept)."""

    name: str
    columns: tuple[str | None, ...]


def _contact_columns() -> tuple[str | None, ...]:
    keep = {
        "penetration_m": "map_penetration_m",
        "surface_velocity_m_per_s": "surface_velocity_m_per_s",
    }
    return tuple(keep.get(f) for f in CONTACT_FIELDS)


def _record_columns() -> tuple[str, ...]:
    names = {
        **{f"{a}_m": f"controller_{a}_m" for a in "xyz"},
        **{f"v{a}_m_per_s": f"controller_v{a}_m_per_s" for a in "xyz"},
        **{f"force_{a}_N": f"controller_force_{a}_N" for a in "xyz"},
        "kappa": "kappa_N_per_m_beta",
        "lambda": "lambda_N_s_per_m_beta1",
    }
    return tuple(names[f] for f in TICK_RECORD_FIELDS)


#: The rig-only log groups: the controller's "tick_record" and "contact"
#: outputs (state: its last tick).
RIG_GROUPS = (
    RigGroup("rig_tick_record", _record_columns()),
    RigGroup("rig_contact", _contact_columns()),
)


def rig_log_ports(controller) -> dict:
    """The output port of each of :data:`RIG_GROUPS`, by group name.

    Args:
        controller: the variable impedance controller (its "tick_record" and
            "contact" outputs are logged).

    Raises:
        VicDrakeError: a port's size is not its group's number of columns.
    """
    ports = {
        "rig_tick_record": controller.GetOutputPort("tick_record"),
        "rig_contact": controller.GetOutputPort("contact"),
    }
    for group in RIG_GROUPS:
        port = ports[group.name]
        if port.size() != len(group.columns):
            raise VicDrakeError(
                f"rig log group {group.name!r}: its port has {port.size()} elements, "
                f"the group names {len(group.columns)}"
            )
    return ports


def rig_frame(logs, root_context) -> pd.DataFrame:
    """The :data:`RIG_SIGNALS` of a scan's logs (one sink: every sample of the scan).

    Args:
        logs: the scan's :class:`~vic_drake.experiments.scan_logs.ScanLogs`
            (holding :data:`RIG_GROUPS`, whose ports :func:`rig_log_ports` gives).
        root_context: the scan diagram's root context after the simulation.
    """
    data = {}
    for group in RIG_GROUPS:
        values = logs.rows(group.name, root_context)
        for i, column in enumerate(group.columns):
            if column is not None:
                data[column] = values[i]
    return pd.DataFrame(data)[list(RIG_SIGNALS)]


def check_bag_scenario(scenario) -> None:
    """Raises VicDrakeError, before simulating, if a scenario's log cannot be a rig log.

    A rig log has one row per controller tick: the log must sample at
    the controller's period.
    """
    log_s, tick_s = scenario.logging.period_s, scenario.controller.period_s
    if not math.isclose(log_s, tick_s, rel_tol=1e-9):
        raise VicDrakeError(
            f"a bag needs one row per controller tick: scenario {scenario.name!r} logs "
            f"every {log_s!r} s (logging.period_s) but its controller ticks every "
            f"{tick_s!r} s (controller.period_s); set them equal"
        )


def rig_log_rows(result) -> pd.DataFrame:
    """A scan's log in the rig's layout (31 columns for VS-CF/VS-VF, 9 for CS/CF).

    Args:
        result: a :class:`~vic_drake.experiments.scan_run.ScanResult`
            (``result.rig`` must hold the rig signals).

    Returns:
        DataFrame of :data:`vic_drake.realdata.CONTROLLER_COLUMNS` or
        :data:`vic_drake.realdata.SCAN_COLUMNS` (see
        :mod:`vic_drake.analysis.rig_layout` for the tick alignment).
    """
    scenario = result.scenario
    check_bag_scenario(scenario)
    if result.rig is None:
        raise VicDrakeError(
            "this scan result holds no rig signals (ScanResult.rig); run it with "
            "vic_drake.experiments.run_scan"
        )
    params = scenario.controller
    if params.reference.controller in ("cs", "cf"):
        return scan_log_rows(
            result.df,
            result.rig,
            sensor_lag_samples=scenario.station.sensor_lag_samples,
        )
    return controller_log_rows(
        result.df,
        result.rig,
        stiffness_z_min_N_per_m=params.qp.stiffness_min_N_per_m[2],
        stiffness_z_max_N_per_m=params.qp.stiffness_max_N_per_m[2],
        eps_max_m=params.reference.eps_max_m,
        tank_min_J=params.tank.min_energy_J,
        power_limit_W=-params.tank.power_limit_W,
        damping_ratio=params.qp.damping_ratio,
        beta=float(result.rig.attrs["beta"]),
    )


def write_scan_bag(result, path: str | os.PathLike) -> Path:
    """Writes a scan as the rig's ROS 2 bag (:func:`rig_log_rows`); returns the folder."""
    return write_bag(rig_log_rows(result), path)


def palpation_log_rows(record, *, surface_z_m: float) -> pd.DataFrame:
    """A simulated palpation (a
    :class:`~vic_drake.experiments.palpation_sim.SimulatedPalpation`) in the
    rig's 6-column palpation layout (:data:`vic_drake.realdata.PALPATION_COLUMNS`):
    the point's surface height ``surface_z_m`` in every row, the tip's
    velocity by central differences, the force as the sensor reads it
    (negative: pressing)."""
    t = np.asarray(record.t_s, float)
    z = np.asarray(record.z_m, float)
    if t.size < 2:
        raise VicDrakeError(f"a palpation log needs 2 samples or more; got {t.size}")
    rows = {
        "t_s": t,
        "surface_z_m": np.full(t.size, float(surface_z_m)),
        "z_target_m": np.asarray(record.z_target_m, float),
        "z_m": z,
        "vz_m_per_s": np.gradient(z, t),
        "force_z_N": -np.asarray(record.force_N, float),
    }
    return pd.DataFrame({c: rows[c] for c in PALPATION_COLUMNS})


def write_palpation_bag(record, path: str | os.PathLike, *, surface_z_m: float) -> Path:
    """Writes a simulated palpation as the rig's ROS 2 bag
    (:func:`palpation_log_rows`); returns the folder."""
    return write_bag(palpation_log_rows(record, surface_z_m=surface_z_m), path)


__all__ = [
    "RIG_GROUPS",
    "RigGroup",
    "check_bag_scenario",
    "palpation_log_rows",
    "rig_frame",
    "rig_log_ports",
    "rig_log_rows",
    "write_palpation_bag",
    "write_scan_bag",
]
