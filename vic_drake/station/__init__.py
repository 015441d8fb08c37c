"""The simulated rig: UR3e, BOTA SensONE F/T sensor, indenter, chest phantom.

- :mod:`vic_drake.station.params` -- :class:`StationParams`, what the rig is
  made of (with Drake's ``MultibodyPlantConfig`` for the plant).
- :mod:`vic_drake.station.servo` -- the UR3e's joint position servo front end.
- :mod:`vic_drake.station.ik` -- probe-tip inverse and forward kinematics.
- :mod:`vic_drake.station.rig` -- :func:`AddRig`, the C++ core (plant, servo,
  lift, gravity feed-forward).
- :mod:`vic_drake.station.builder` -- :func:`MakeStation`, the Diagram.

The arm and tool models are :mod:`vic_drake.models.ur3e` (re-exported here).
"""

from vic_drake.models.ur3e import (
    UR3E_JOINTS,
    AddTool,
    AddUr3e,
    ArmHandles,
    MakeUr3ePlant,
    probe_down_rotation,
)
from vic_drake.station.builder import MakeStation, set_station_state, station_plant
from vic_drake.station.ik import (
    DEFAULT_Q_SEED,
    FALLBACK_Q_SEEDS,
    initial_q_for_tip,
    probe_pose,
    solve_tip_ik,
)
from vic_drake.station.params import StationParams
from vic_drake.station.rig import AddRig, Rig
from vic_drake.station.servo import (
    joint_filter_step,
    joint_servo_rest_state,
    joint_servo_system_matrices,
)

__all__ = [
    "DEFAULT_Q_SEED",
    "FALLBACK_Q_SEEDS",
    "UR3E_JOINTS",
    "AddTool",
    "AddUr3e",
    "ArmHandles",
    "AddRig",
    "MakeStation",
    "Rig",
    "MakeUr3ePlant",
    "StationParams",
    "initial_q_for_tip",
    "joint_filter_step",
    "joint_servo_rest_state",
    "joint_servo_system_matrices",
    "probe_down_rotation",
    "probe_pose",
    "set_station_state",
    "solve_tip_ik",
    "station_plant",
]
