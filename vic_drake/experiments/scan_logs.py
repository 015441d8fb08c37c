"""What a closed-loop scan logs, and how the logs become the canonical frame.

Each :class:`LogGroup` names one output port of the scan diagram, the names
of that port's elements (its layout, as the system documents it) and, by
element name, the canonical column each kept element fills (the columns of
:data:`vic_drake.analysis.columns.CANONICAL_COLUMNS`, a contract). Elements not
listed in ``columns`` are logged but not kept.

:func:`AddScanLogs` records every group (these and the rig's,
:mod:`vic_drake.experiments.rig_log`) with one VectorLogSink behind one C++
Multiplexer; the :class:`ScanLogs` it returns reads each group's rows back by
name.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
import pandas as pd
from pydrake.systems.primitives import LogVectorOutput, Multiplexer

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
        {"qp_ok": "qp_ok", "fault": "qp_fault", "in_contact": "in_contact"},
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


def log_group_ports(systems: Mapping, *, lateral: bool) -> dict:
    """The output port of each of ``log_groups(lateral)``, by group name.

    Args:
        systems: {name: system} of the scan diagram's subsystems that own
            the groups' ports (each group's ``source``).
        lateral: whether the lateral group is logged.

    Raises:
        VicDrakeError: a port's size is not its group's number of fields.
    """
    ports = {}
    for group in log_groups(lateral):
        port = systems[group.source].GetOutputPort(group.port)
        if port.size() != len(group.fields):
            raise VicDrakeError(
                f"log group {group.name!r}: port {group.source}.{group.port} has "
                f"{port.size()} elements, the group names {len(group.fields)}"
            )
        ports[group.name] = port
    return ports


class ScanLogs:
    """The scan's log groups, recorded by one VectorLogSink.

    The sink records the groups' ports stacked in one vector (see
    :func:`AddScanLogs`); each group's rows are its slice of the sink's.

    Attributes:
        sink: the VectorLogSink.
    """

    def __init__(self, sink, slices: Mapping[str, slice]):
        self.sink = sink
        self._slices = dict(slices)

    @property
    def names(self) -> tuple[str, ...]:
        """The logged groups' names, in the sink's order."""
        return tuple(self._slices)

    def __contains__(self, name: object) -> bool:
        return name in self._slices

    def times(self, root_context) -> np.ndarray:
        """The sample times, s (read-only view of the log)."""
        return self.sink.FindLog(root_context).sample_times()

    def rows(self, name: str, root_context) -> np.ndarray:
        """Group ``name``'s samples, (its port's elements, samples).

        A read-only view of the log recorded in ``root_context`` (the scan
        diagram's root context after the simulation).
        """
        if name not in self._slices:
            raise VicDrakeError(
                f"no log group {name!r}; the scan logs {list(self._slices)}"
            )
        return self.sink.FindLog(root_context).data()[self._slices[name]]


def AddScanLogs(builder, ports: Mapping, *, period_s: float) -> ScanLogs:
    """Logs ``ports`` through one C++ Multiplexer ("scan_log_inputs") and one
    VectorLogSink ("scan_log"): one publish event per sample for all of them.

    Args:
        builder: the scan diagram's DiagramBuilder.
        ports: {group name: output port}, in the order they are stacked.
        period_s: the sink's sampling period, s (``scenario.logging.period_s``).
    """
    sizes = [port.size() for port in ports.values()]
    mux = builder.AddNamedSystem("scan_log_inputs", Multiplexer(sizes))
    for i, port in enumerate(ports.values()):
        builder.Connect(port, mux.get_input_port(i))
    sink = LogVectorOutput(mux.get_output_port(0), builder, period_s)
    sink.set_name("scan_log")
    ends = np.cumsum(sizes).tolist()
    starts = [0, *ends[:-1]]
    return ScanLogs(
        sink,
        {name: slice(a, b) for name, a, b in zip(ports, starts, ends, strict=True)},
    )


def logs_to_frame(logs: ScanLogs, root_context) -> pd.DataFrame:
    """The logs as one DataFrame of the canonical columns.

    Args:
        logs: the scan's :class:`ScanLogs` (holding :data:`LOG_GROUPS`, and
            :data:`LATERAL_LOG_GROUP`, whose :data:`LATERAL_COLUMNS` then
            follow the canonical ones).
        root_context: the scan diagram's root context after the simulation.
    """
    lateral = LATERAL_LOG_GROUP.name in logs
    data = {"t_s": logs.times(root_context).copy()}
    for group in log_groups(lateral):
        values = logs.rows(group.name, root_context)
        for i, column in group.kept():
            data[column] = values[i]
    df = pd.DataFrame(data)
    return df[list(CANONICAL_COLUMNS) + (list(LATERAL_COLUMNS) if lateral else [])]


__all__ = [
    "JOINTS",
    "LATERAL_COLUMNS",
    "LATERAL_LOG_GROUP",
    "LOG_GROUPS",
    "XYZ",
    "AddScanLogs",
    "LogGroup",
    "ScanLogs",
    "log_group_ports",
    "log_groups",
    "logs_to_frame",
]
