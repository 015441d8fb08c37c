"""The phantom's vertical offset over time: lifts by hand or a logged table."""

import math
from dataclasses import dataclass, field

from vic_drake.errors import VicDrakeError, check_number


@dataclass
class PhantomLift:
    """One lift of the phantom (the paper's "raising the dummy" by hand).

    The phantom rises by ``height_m`` over ``rise_s`` from ``start_s``,
    stays up for ``hold_s`` and comes down over ``fall_s`` (smooth
    cosine ramps).
    """

    start_s: float = 4.0  # Start of the rise, s.
    height_m: float = 0.02  # Rise of the phantom, m (> 0 lifts it).
    rise_s: float = 1.0  # Duration of the rise, s (> 0).
    hold_s: float = 1.0  # Time at full height, s.
    fall_s: float = 1.0  # Duration of the descent, s (> 0).

    def __post_init__(self):
        self.validate()

    def validate(self) -> "PhantomLift":
        """Checks every field; returns self.

        Raises:
            VicDrakeError: naming the field and the bad value.
        """
        o = "PhantomLift"
        check_number(o, "start_s", self.start_s, low=0.0)
        check_number(o, "height_m", self.height_m, low=-0.1, high=0.1)
        check_number(o, "rise_s", self.rise_s, low=0.0, low_open=True)
        check_number(o, "hold_s", self.hold_s, low=0.0)
        check_number(o, "fall_s", self.fall_s, low=0.0, low_open=True)
        return self


@dataclass
class DisturbanceConfig:
    """Vertical offset of the phantom over time (0 everywhere: nominal).

    Either a list of :class:`PhantomLift` (summed) or a ``table`` of
    ``[t_s, z_offset_m]`` rows, linearly interpolated and held constant
    outside its time range (e.g. estimated from a real ``_dist`` log). Not
    both.
    """

    lifts: list[PhantomLift] = field(default_factory=list)  # Lift profiles, summed.
    table: list[list[float]] = field(default_factory=list)  # [t_s, z_offset_m] rows.

    def __post_init__(self):
        self.validate()

    def validate(self) -> "DisturbanceConfig":
        """Checks every field (and every lift); returns self.

        Raises:
            VicDrakeError: naming the field and the bad value.
        """
        o = "DisturbanceConfig"
        for i, lift in enumerate(self.lifts):
            if not isinstance(lift, PhantomLift):
                raise VicDrakeError(
                    f"{o}.lifts[{i}] must be a PhantomLift; got {lift!r}"
                )
            lift.validate()
        if self.lifts and self.table:
            raise VicDrakeError(f"{o}: give either lifts or table, not both")
        prev = -math.inf
        for i, row in enumerate(self.table):
            if len(row) != 2:
                raise VicDrakeError(
                    f"{o}.table[{i}] must be [t_s, z_offset_m]; got {row!r}"
                )
            t = check_number(o, f"table[{i}][0]", row[0])
            check_number(o, f"table[{i}][1]", row[1], low=-0.1, high=0.1)
            if not t > prev:
                raise VicDrakeError(
                    f"{o}.table times must increase; row {i} has t = {t!r}"
                )
            prev = t
        return self

    @property
    def is_nominal(self) -> bool:
        """True when the phantom never moves."""
        return not self.lifts and not self.table
