"""What a closed-loop scan logs, and how the logs become the canonical frame.

Each :class:`LogGroup` names one output port of the scan diagram, the names
of that port's elements (its layout, as the system documents it) and, by
element name, the canonical column each kept element fills (the columns of
:data:`vic_drake.analysis.columns.CANONICAL_COLUMNS`, a contract). Elements not
listed in ``columns`` are logged but not kept.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import pandas as pd

from vic_drake.analysis.columns import CANONICAL_COLUMNS
from vic_drake.errors import VicDrakeError
from vic_drake.systems.signals import STATUS_FIELDS, TANK_FIELDS
from vic_drake.systems.tissue_force import SAMPLE_FIELDS

#: Layout of a 3-vector port in W.
XYZ = ("x", "y", "z")
#: Layout of the joint-command port: the six UR3e joints, base to wrist.
JOINTS = tuple(f"q{i}" for i in range(6))


class LogGroup(NamedTuple):
    """One logged output port of the scan diagram.

    Attributes:
        name: group name; the VectorLogSink is named ``log_{name}``.
        source: the scan diagram's subsystem that owns the port.
        port: the output port's name.
        fields: the names of the port's elements, in order.
        columns: {field: canonical column} of the elements kept.
    """

    name: str
    source: str
    port: str
    fields: tuple[str, ...]
    columns: Mapping[str, str]

    def kept(self) -> list[tuple[int, str]]:
        """(element index, column) of every kept element, in port order."""
        unknown = set(self.columns) - set(self.fields)
        if unknown:
            raise VicDrakeError(
                f"log group {self.name!r}: fields {sorted(unknown)} are not elements "
                f"of {self.port!r} {self.fields}"
            )
        return [
            (i, self.columns[f]) for i, f in enumerate(self.fields) if f in self.columns
        ]


def _xyz(*columns: str) -> dict[str, str]:
    return dict(zip(XYZ, columns, strict=True))


#: Logged signal groups of the scan diagram (see :func:`logs_to_frame`).
LOG_GROUPS = (
    # The tip and the tissue as the tissue element stores them after each
    # tick: logging them costs no recomputation.
    LogGroup(
        "tissue",
        "station",
        "tissue.sample",
        SAMPLE_FIELDS,
        {
            "x_m": "x_m",
            "y_m": "y_m",
            "z_m": "z_m",
            "force_z_N": "force_tissue_z_N",
            "penetration_m": "penetration_m",
            "surface_z_m": "surface_z_m",
        },
    ),
    LogGroup(
        "target", "target", "target_position", XYZ, _xyz("x_d_m", "y_d_m", "z_d_m")
    ),
    LogGroup(
        "sensor_force",
        "station",
        "ft_sensor.force_W",
        XYZ,
        _xyz("force_sensor_x_N", "force_sensor_y_N", "force_sensor_z_N"),
    ),
    LogGroup(
        "phantom_lift",
        "station",
        "phantom.z_offset",
        ("z_offset",),
        {"z_offset": "phantom_lift_m"},
    ),
    LogGroup(
        "force_reference",
        "variable_impedance_controller",
        "force_reference",
        XYZ,
        {"z": "force_ref_z_N"},
    ),
    LogGroup(
        "force_min",
        "variable_impedance_controller",
        "force_min",
        XYZ,
        {"z": "force_min_z_N"},
    ),
    LogGroup(
        "stiffness",
        "variable_impedance_controller",
        "stiffness",
        XYZ,
        _xyz("stiffness_x_N_per_m", "stiffness_y_N_per_m", "stiffness_z_N_per_m"),
    ),
    LogGroup(
        "tank",
        "variable_impedance_controller",
        "tank",
        TANK_FIELDS,
        dict(
            zip(
                TANK_FIELDS,
                ("tank_energy_J", "tank_power_W", "tank_sigma", "tank_enabled"),
                strict=True,
            )
        ),
    ),
    LogGroup(
        "status",
        "variable_impedance_controller",
        "status",
        STATUS_FIELDS,
        {"qp_ok": "qp_ok", "in_contact": "in_contact"},
    ),
    LogGroup(
        "q_cmd",
        "fdcc",
        "position_command",
        JOINTS,
        {q: f"q_cmd_{i}_rad" for i, q in enumerate(JOINTS)},
    ),
)


#: Logged only when the phantom moves laterally (a lateral breathing part):
#: its x, y offset, as columns after the canonical ones.
LATERAL_LOG_GROUP = LogGroup(
    "phantom_lateral",
    "station",
    "phantom.lateral_offset",
    ("x", "y"),
    {"x": "phantom_x_m", "y": "phantom_y_m"},
)
#: The columns :data:`LATERAL_LOG_GROUP` adds.
LATERAL_COLUMNS = tuple(LATERAL_LOG_GROUP.columns.values())


def log_groups(lateral: bool) -> tuple[LogGroup, ...]:
    """The scan's log groups: :data:`LOG_GROUPS`, and the lateral one if asked."""
    return (*LOG_GROUPS, LATERAL_LOG_GROUP) if lateral else LOG_GROUPS


def logs_to_frame(loggers: dict, root_context) -> pd.DataFrame:
    """The loggers' records as one DataFrame of the canonical columns.

    Args:
        loggers: {group name: VectorLogSink} of :data:`LOG_GROUPS` (and of
            :data:`LATERAL_LOG_GROUP`, whose :data:`LATERAL_COLUMNS` then
            follow the canonical ones).
        root_context: the scan diagram's root context after the simulation.
    """
    lateral = LATERAL_LOG_GROUP.name in loggers
    data = {}
    t = None
    for group in log_groups(lateral):
        log = loggers[group.name].FindLog(root_context)
        if t is None:
            t = log.sample_times().copy()
        values = log.data()
        n = min(values.shape[1], len(t))
        for i, column in group.kept():
            data[column] = values[i, :n]
    n = min(len(v) for v in data.values())
    df = pd.DataFrame({"t_s": t[:n], **{k: v[:n] for k, v in data.items()}})
    return df[list(CANONICAL_COLUMNS) + (list(LATERAL_COLUMNS) if lateral else [])]


__all__ = [
    "JOINTS",
    "LATERAL_COLUMNS",
    "LATERAL_LOG_GROUP",
    "LOG_GROUPS",
    "XYZ",
    "LogGroup",
    "log_groups",
    "logs_to_frame",
]
