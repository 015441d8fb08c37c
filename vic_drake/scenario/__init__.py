"""The typed scenario of a scan: everything one closed-loop run needs.

A :class:`Scenario` is a tree of config dataclasses, one concept per module:
:mod:`.phantom` (which tissue), :mod:`.trajectory` (the target x_d(t)),
:mod:`.disturbance` (phantom lifts), :mod:`.logging` (what is recorded) and
:mod:`.scenario` (the whole tree, with the station, controller, FDCC and
Drake's ``SimulatorConfig``). :mod:`.io` loads and dumps it with Drake's
``yaml_load_typed`` / ``yaml_dump_typed``; the files in ``diagrams/`` are
the paper's scenarios.
"""

from vic_drake.scenario.disturbance import DisturbanceConfig, PhantomLift
from vic_drake.scenario.io import (
    dumps_scenario,
    load_scenario,
    loads_scenario,
    save_scenario,
)
from vic_drake.scenario.logging import LoggingConfig
from vic_drake.scenario.phantom import PhantomConfig
from vic_drake.scenario.plain import as_plain, differences
from vic_drake.scenario.scenario import SCAN_QP_SOLVER, Scenario
from vic_drake.scenario.trajectory import TrajectoryConfig

__all__ = [
    "SCAN_QP_SOLVER",
    "DisturbanceConfig",
    "LoggingConfig",
    "PhantomConfig",
    "PhantomLift",
    "Scenario",
    "TrajectoryConfig",
    "as_plain",
    "differences",
    "dumps_scenario",
    "load_scenario",
    "loads_scenario",
    "save_scenario",
]
