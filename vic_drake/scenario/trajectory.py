"""The target x_d(t) a scan's controller tracks: a parametric scan or a table."""

from dataclasses import dataclass, field

from vic_drake.errors import VicDrakeError, check_number

#: Largest lift-off, m: more is a length typed in mm (48 for 0.048).
MAX_LIFTOFF_M = 0.2
#: Largest approach and scan speed, m/s (the rig scanned at 0.01): more is
#: a speed typed in mm/s.
MAX_SPEED_M_PER_S = 0.1


@dataclass
class TrajectoryConfig:
    """The target (x_d) the controller tracks, in the robot base frame W.

    Parametric profile (used when ``waypoints`` is empty), as the real scans:
    the target starts at (start_x_m, y_m, approach_z_m), waits
    ``start_delay_s``, descends at ``approach_speed_m_per_s`` to
    ``target_z_m``, waits ``dwell_s``, moves along x to ``end_x_m`` at
    ``scan_speed_m_per_s``, waits ``end_dwell_s`` and is then raised by
    ``liftoff_height_m`` over ``liftoff_s`` (0: a step, as the real rig did).

    ``waypoints`` replaces the profile by a table of rows
    ``[t_s, x_m, y_m, z_m]`` interpolated linearly (e.g. the target logged
    by the real controller).

    Attributes:
        start_x_m: target x at the start, m (real scans: 0.036).
        end_x_m: target x at the end of the scan, m (real: -0.164).
        y_m: target y, m (real: -0.36).
        approach_z_m: target z before the approach, m. Equal to target_z_m
            for no approach (the CS/CF logs start in contact).
        target_z_m: constant target z during the scan, m, below the surface
            so the probe stays in contact (real rig: 0.085).
        start_delay_s: hold at the start before the approach, s.
        approach_speed_m_per_s: descent speed of the target, m/s (> 0).
        dwell_s: hold at target_z_m before moving along x, s.
        scan_speed_m_per_s: speed along x, m/s (> 0; real: 0.01).
        end_dwell_s: hold at the end of the scan before lift-off, s.
        liftoff_height_m: rise of the target at the end, m (0: no lift-off).
        liftoff_s: duration of the rise, s (0: a step).
        initial_tip_z_m: tip height the robot starts at (IK), m; None means
            approach_z_m. The CS/CF logs start with the probe resting on the
            surface above a target below it.
        waypoints: optional table of [t_s, x_m, y_m, z_m] rows (t increasing).
    """

    start_x_m: float = 0.036  # Target x at the start of the scan, m.
    end_x_m: float = -0.164  # Target x at the end of the scan, m.
    y_m: float = -0.36  # Target y, m.
    approach_z_m: float = 0.108  # Target z before the approach, m.
    target_z_m: float = 0.085  # Constant target z during the scan, m.
    start_delay_s: float = 0.0  # Hold before the approach, s.
    approach_speed_m_per_s: float = 0.01  # Descent speed of the target, m/s.
    dwell_s: float = 0.0  # Hold at target_z_m before the scan, s.
    scan_speed_m_per_s: float = 0.01  # Speed along x, m/s.
    end_dwell_s: float = 0.0  # Hold at the end of the scan, s.
    liftoff_height_m: float = 0.048  # Rise of the target at the end, m.
    liftoff_s: float = 0.0  # Duration of the rise, s (0: a step).
    initial_tip_z_m: float | None = None  # Initial tip z, m (None: approach_z_m).
    waypoints: list[list[float]] = field(default_factory=list)  # [t_s, x, y, z] rows.

    def __post_init__(self):
        self.validate()

    def validate(self) -> "TrajectoryConfig":
        """Checks every field; returns self.

        Raises:
            VicDrakeError: naming the field and the bad value.
        """
        o = "TrajectoryConfig"
        for name in ("start_x_m", "end_x_m", "y_m", "approach_z_m", "target_z_m"):
            check_number(o, name, getattr(self, name))
        for name in ("start_delay_s", "dwell_s", "end_dwell_s", "liftoff_s"):
            check_number(o, name, getattr(self, name), low=0.0)
        if check_number(o, "liftoff_height_m", self.liftoff_height_m, low=0.0) > (
            MAX_LIFTOFF_M
        ):
            raise VicDrakeError(
                f"{o}.liftoff_height_m is in metres and must be at most "
                f"{MAX_LIFTOFF_M:g} m; got {self.liftoff_height_m!r} (0.05 is 5 cm)"
            )
        for name in ("approach_speed_m_per_s", "scan_speed_m_per_s"):
            value = check_number(o, name, getattr(self, name), low=0.0, low_open=True)
            if value > MAX_SPEED_M_PER_S:
                raise VicDrakeError(
                    f"{o}.{name} is in m/s and must be at most "
                    f"{MAX_SPEED_M_PER_S:g} m/s; got {value!r} (0.01 is 1 cm/s)"
                )
        if self.approach_z_m < self.target_z_m:
            raise VicDrakeError(
                f"{o}.approach_z_m ({self.approach_z_m!r}) must be >= target_z_m "
                f"({self.target_z_m!r}): the target approaches from above"
            )
        if self.initial_tip_z_m is not None:
            check_number(o, "initial_tip_z_m", self.initial_tip_z_m)
        if self.waypoints:
            self._validate_waypoints(o)
        return self

    def _validate_waypoints(self, o: str) -> None:
        rows = [list(r) for r in self.waypoints]
        for i, r in enumerate(rows):
            if len(r) != 4:
                raise VicDrakeError(
                    f"{o}.waypoints[{i}] must be [t_s, x_m, y_m, z_m]; got {r!r}"
                )
            for j, v in enumerate(r):
                check_number(o, f"waypoints[{i}][{j}]", v)
        if len(rows) < 2:
            raise VicDrakeError(f"{o}.waypoints needs at least 2 rows; got {len(rows)}")
        ts = [r[0] for r in rows]
        for i in range(1, len(ts)):
            if not ts[i] > ts[i - 1]:
                raise VicDrakeError(
                    f"{o}.waypoints times must increase; row {i} has t = {ts[i]!r} "
                    f"after {ts[i - 1]!r}"
                )

    @property
    def start_tip_z_m(self) -> float:
        """Tip height the robot starts at, m."""
        if self.initial_tip_z_m is not None:
            return float(self.initial_tip_z_m)
        if self.waypoints:
            return float(self.waypoints[0][3])
        return float(self.approach_z_m)

    @property
    def start_xyz_m(self) -> tuple[float, float, float]:
        """Target position at t = 0, m."""
        if self.waypoints:
            r = self.waypoints[0]
            return (float(r[1]), float(r[2]), float(r[3]))
        return (float(self.start_x_m), float(self.y_m), float(self.approach_z_m))

    @property
    def end_time_s(self) -> float:
        """Time at which the target stops moving (after lift-off), s."""
        if self.waypoints:
            return float(self.waypoints[-1][0])
        t = (
            self.start_delay_s
            + (self.approach_z_m - self.target_z_m) / self.approach_speed_m_per_s
        )
        t += self.dwell_s + abs(self.end_x_m - self.start_x_m) / self.scan_speed_m_per_s
        t += self.end_dwell_s
        if self.liftoff_height_m > 0:
            t += self.liftoff_s
        return t
