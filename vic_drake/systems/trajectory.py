"""Reference sources of a scan: the target x_d(t) and the phantom lift.

Pure functions build the profiles from the scenario
(:func:`target_knots`, :func:`phantom_lift_m`); two thin LeafSystems expose
them as ports:

- :class:`TargetTrajectorySource`: outputs "target_position" (3, m) and
  "target_velocity" (3, m/s) of a piecewise-linear target (a first-order-hold
  ``PiecewisePolynomial``), evaluated by Drake's C++ ``TrajectorySource``.
- :class:`PhantomLiftSource`: output "phantom_lift" (1, m), the vertical
  offset of the phantom (0 in nominal runs).

Both are stateless functions of time. The configurations are
:class:`vic_drake.scenario.TrajectoryConfig` and
:class:`vic_drake.scenario.DisturbanceConfig`; the scenario layer sits above
this one, so they are read by their fields (checked here), not imported.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from vic_drake.errors import VicDrakeError

#: The fields of a TrajectoryConfig that the target reads.
_TRAJECTORY_FIELDS = (
    "waypoints", "start_x_m", "end_x_m", "y_m", "approach_z_m", "target_z_m",
    "start_delay_s", "approach_speed_m_per_s", "dwell_s", "scan_speed_m_per_s",
    "end_dwell_s", "liftoff_height_m", "liftoff_s",
)  # fmt: skip
#: The fields of a DisturbanceConfig that the lift reads.
_DISTURBANCE_FIELDS = ("table", "lifts")


def _check_config(config, fields, owner: str, kind: str) -> None:
    """Raises VicDrakeError unless config has every field of a ``kind``."""
    if not all(hasattr(config, name) for name in fields):
        raise VicDrakeError(f"{owner} needs a {kind}; got {config!r}")


def target_knots(config) -> tuple[np.ndarray, np.ndarray]:
    """Knots of the piecewise-linear target.

    Args:
        config: the trajectory (parametric profile or waypoint table).

    Returns:
        (t_s, p_m): times (n,) increasing, positions (3, n) in W. Steps (a
        lift-off with ``liftoff_s = 0``) are a 1 ms ramp.
    """
    if config.waypoints:
        table = np.asarray(config.waypoints, dtype=float)
        return table[:, 0].copy(), table[:, 1:4].T.copy()
    c = config
    t = [0.0]
    p = [(c.start_x_m, c.y_m, c.approach_z_m)]

    def add(dt, xyz):
        if dt > 0:
            t.append(t[-1] + dt)
            p.append(xyz)

    add(c.start_delay_s, p[-1])
    add(
        (c.approach_z_m - c.target_z_m) / c.approach_speed_m_per_s,
        (c.start_x_m, c.y_m, c.target_z_m),
    )
    add(c.dwell_s, p[-1])
    add(
        abs(c.end_x_m - c.start_x_m) / c.scan_speed_m_per_s,
        (c.end_x_m, c.y_m, c.target_z_m),
    )
    add(c.end_dwell_s, p[-1])
    if c.liftoff_height_m > 0:
        add(
            max(c.liftoff_s, 1e-3),
            (c.end_x_m, c.y_m, c.target_z_m + c.liftoff_height_m),
        )
    if len(t) == 1:  # Motionless target: hold it.
        add(1.0, p[-1])
    return np.asarray(t), np.asarray(p, dtype=float).T


def _smoothstep(u: np.ndarray) -> np.ndarray:
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def phantom_lift_m(t_s, config) -> np.ndarray:
    """Phantom z offset at times t_s, m (vectorised).

    Lifts rise and fall along smoothstep ramps (zero slope at both ends) and
    add up; a table is interpolated linearly and held outside its range.
    """
    t = np.asarray(t_s, dtype=float)
    if config.table:
        table = np.asarray(config.table, dtype=float)
        return np.interp(t, table[:, 0], table[:, 1])
    z = np.zeros_like(t)
    for lift in config.lifts:
        up = _smoothstep((t - lift.start_s) / lift.rise_s)
        t_fall = lift.start_s + lift.rise_s + lift.hold_s
        down = _smoothstep((t - t_fall) / lift.fall_s)
        z = z + lift.height_m * (up - down)
    return z


def _velocity_trajectory(position: PiecewisePolynomial) -> PiecewisePolynomial:
    """The rate of ``position`` (piecewise constant), zero from its end time on.

    The derivative's segments followed by a zero segment [t_end, t_end + 1 s]:
    a break belongs to the segment it starts and a ``PiecewisePolynomial``
    holds its last segment past its end, so the value is zero at t_end and
    after.
    """
    velocity = position.derivative(1)
    t_end = position.end_time()
    velocity.ConcatenateInTime(
        PiecewisePolynomial.ZeroOrderHold(
            [t_end, t_end + 1.0], np.zeros((position.rows(), 2))
        )
    )
    return velocity


class TargetTrajectorySource(Diagram):
    """The scan target x_d(t) from a :class:`TrajectoryConfig`.

    A Diagram of two C++ ``TrajectorySource`` systems ("position" and
    "velocity"): no Python runs when its outputs are evaluated.

    Output ports:
        target_position: (3,) x_d in W, m (held at the last knot after the
            end).
        target_velocity: (3,) its rate in W, m/s (piecewise constant; zero
            from the end time on).
    """

    def __init__(self, config):
        super().__init__()
        _check_config(
            config, _TRAJECTORY_FIELDS, "TargetTrajectorySource", "TrajectoryConfig"
        )
        t, p = target_knots(config)
        self._trajectory = PiecewisePolynomial.FirstOrderHold(t, p)
        builder = DiagramBuilder()
        position = builder.AddNamedSystem(
            "position", TrajectorySource(self._trajectory)
        )
        velocity = builder.AddNamedSystem(
            "velocity", TrajectorySource(_velocity_trajectory(self._trajectory))
        )
        builder.ExportOutput(position.get_output_port(), "target_position")
        builder.ExportOutput(velocity.get_output_port(), "target_velocity")
        builder.BuildInto(self)
        self._position_port = self.GetOutputPort("target_position")
        self._velocity_port = self.GetOutputPort("target_velocity")

    @property
    def trajectory(self):
        """The PiecewisePolynomial of the target position (3 rows)."""
        return self._trajectory

    def get_target_position_output_port(self):
        return self._position_port

    def get_target_velocity_output_port(self):
        return self._velocity_port


class PhantomLiftSource(LeafSystem):
    """The phantom's vertical offset from a :class:`DisturbanceConfig`.

    Output ports:
        phantom_lift: (1,) z offset of the phantom, m.
    """

    def __init__(self, config):
        super().__init__()
        _check_config(
            config, _DISTURBANCE_FIELDS, "PhantomLiftSource", "DisturbanceConfig"
        )
        self._config = config
        self._port = self.DeclareVectorOutputPort(
            "phantom_lift", BasicVector(1), self._calc
        )

    def get_phantom_lift_output_port(self):
        return self._port

    def _calc(self, context, output):
        output.SetAtIndex(0, float(phantom_lift_m(context.get_time(), self._config)))


__all__ = [
    "PhantomLiftSource",
    "TargetTrajectorySource",
    "phantom_lift_m",
    "target_knots",
]
