"""What a scan records: the sampling of its signal loggers."""

from dataclasses import dataclass

from vic_drake.errors import check_number


@dataclass
class LoggingConfig:
    """What is recorded."""

    period_s: float = 0.002  # Sampling period of the loggers, s (real logs: 500 Hz).

    def __post_init__(self):
        self.validate()

    def validate(self) -> "LoggingConfig":
        """Checks every field; returns self.

        Raises:
            VicDrakeError: naming the field and the bad value.
        """
        check_number("LoggingConfig", "period_s", self.period_s, low=0.0, low_open=True)
        return self
