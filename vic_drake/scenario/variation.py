"""What varies between patients and runs: anatomy, motion, sensor faults, map.

:class:`VariationConfig` is the scenario's ``variations`` field. Each part
is off by default, so a scenario without it runs the paper's scan unchanged:

- ``patient``: a synthetic patient's chest
  (:mod:`vic_drake.tissue.phantom.population`, ranges documented there);
- ``motion``: breathing (optionally with a small lateral part) and a
  replayed motion trace, added to the scenario's phantom lifts
  (:mod:`vic_drake.tissue.motion`);
- ``sensor_faults``: faults of the force reading the controllers see
  (:mod:`vic_drake.control.sensor_faults`); the station's own sensor and the
  logs keep the true reading;
- ``map_errors``: errors of the map the controller reads
  (:mod:`vic_drake.tissue.phantom.distorted`); the tissue stays true.
"""

from dataclasses import dataclass, field

from vic_drake.control.sensor_faults import DROPOUT_MODES
from vic_drake.errors import VicDrakeError, check_number
from vic_drake.tissue.motion import load_motion_trace
from vic_drake.tissue.phantom.population import (
    POPULATION_RANGES,
    check_patient_factors,
)


def _check_int(owner: str, name: str, value, low: int, high: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise VicDrakeError(
            f"{owner}.{name} must be an integer >= {low}; got {value!r}"
        )
    if high is not None and value > high:
        raise VicDrakeError(f"{owner}.{name} must be <= {high}; got {value!r}")
    return value


@dataclass
class PatientConfig:
    """A synthetic patient (phantom.kind must be "synthetic" when enabled).

    Defaults are the reference chest (the measured phantom's anchors); see
    :data:`vic_drake.tissue.phantom.population.POPULATION_RANGES` for the
    population's range of each factor.
    """

    enabled: bool = False  # Replace the reference chest by this patient's.
    kappa_scale: float = 1.0  # kappa everywhere x this.
    lam_scale: float = 1.0  # lambda everywhere x this.
    rib_stiffness_scale: float = 1.0  # Ribs' stiffness rise x this.
    rib_depth_m: float = POPULATION_RANGES["rib_depth_m"][0]  # Tissue over ribs, m.
    rib_spacing_scale: float = 1.0  # Intercostal spacing x this.
    rib_width_scale: float = 1.0  # Rib band half-width x this.
    soft_tissue_offset_m: float = 0.0  # Body wall thicker by this (surface up), m.
    curvature_scale: float = 1.0  # Dome curvature x this.
    shoulder_scale: float = 1.0  # Height of the shoulder hump x this.
    texture_seed: int = 7  # Seed of the soft-tissue texture.

    def __post_init__(self):
        self.validate()

    def factors(self) -> dict:
        """The patient factors (everything but ``enabled``) by name."""
        return {k: getattr(self, k) for k in (*POPULATION_RANGES, "texture_seed")}

    def validate(self) -> "PatientConfig":
        o = "PatientConfig"
        if not isinstance(self.enabled, bool):
            raise VicDrakeError(
                f"{o}.enabled must be true or false; got {self.enabled!r}"
            )
        check_patient_factors(
            {k: v for k, v in self.factors().items() if k != "texture_seed"}, o
        )
        _check_int(o, "texture_seed", self.texture_seed, 0)
        return self


#: Largest |lateral excursion| of a breath per axis, m: a small lateral part.
LATERAL_BREATHING_MAX_M = 0.01


@dataclass
class BreathingConfig:
    """Breathing: a periodic surface motion along the chest's normal (W z),
    optionally with a small lateral part (W x, y).

    Typical adult breathing: 0.2-0.33 Hz, 5-15 mm. ``amplitude_m`` = 0 and
    ``lateral_amplitude_m`` = [0, 0] is off. A lateral part moves the
    phantom in x and y with the breath (same raised cosine, in phase, each
    breath's excursion scaled as its depth); the station then has lateral
    joints under the phantom (only then).
    """

    frequency_hz: float = 0.25  # Mean breathing rate, Hz.
    amplitude_m: float = 0.0  # Mean peak-to-peak surface excursion, m (0: off).
    irregularity: float = 0.0  # Relative std of each breath's period and depth.
    seed: int = 0  # Seed of the irregular breaths.
    # Peak-to-peak excursion of a mean breath along W x and y, m, signed
    # (|each| <= 0.01 m; [0, 0]: vertical breathing only).
    lateral_amplitude_m: list[float] = field(default_factory=lambda: [0.0, 0.0])

    def __post_init__(self):
        self.validate()

    def validate(self) -> "BreathingConfig":
        o = "BreathingConfig"
        check_number(o, "frequency_hz", self.frequency_hz, low=0.05, high=1.0)
        check_number(o, "amplitude_m", self.amplitude_m, low=0.0, high=0.04)
        check_number(o, "irregularity", self.irregularity, low=0.0, high=0.5)
        _check_int(o, "seed", self.seed, 0)
        lateral = self.lateral_amplitude_m
        if not isinstance(lateral, (list, tuple)) or len(lateral) != 2:
            raise VicDrakeError(
                f"{o}.lateral_amplitude_m must be 2 numbers [x, y] (m); got {lateral!r}"
            )
        m = LATERAL_BREATHING_MAX_M
        for i, value in enumerate(lateral):
            name = f"lateral_amplitude_m[{i}]"
            if abs(check_number(o, name, value)) > m:
                raise VicDrakeError(
                    f"{o}.{name} must be within [-{m}, {m}] m (a small lateral "
                    f"part of the breath); got {value!r}"
                )
        return self

    @property
    def lateral_active(self) -> bool:
        """The breath moves the phantom in x or y too."""
        return any(v != 0 for v in self.lateral_amplitude_m)

    @property
    def active(self) -> bool:
        return self.amplitude_m > 0 or self.lateral_active


@dataclass
class PatientMotionConfig:
    """Patient motion added to the scenario's phantom lifts (``disturbance``)."""

    breathing: BreathingConfig = field(default_factory=BreathingConfig)
    # CSV file with the header "t_s,z_m": a vertical motion replayed (linear
    # between rows, held outside them); "" for none. Relative paths are
    # taken from the working directory.
    trace_csv: str = ""
    trace_scale: float = 1.0  # The trace's z x this.

    def __post_init__(self):
        self.validate()

    def validate(self) -> "PatientMotionConfig":
        o = "PatientMotionConfig"
        if not isinstance(self.breathing, BreathingConfig):
            raise VicDrakeError(f"{o}.breathing must be a BreathingConfig")
        self.breathing.validate()
        if not isinstance(self.trace_csv, str):
            raise VicDrakeError(
                f"{o}.trace_csv must be a path string; got {self.trace_csv!r}"
            )
        if self.trace_csv:
            load_motion_trace(self.trace_csv)
        check_number(o, "trace_scale", self.trace_scale, low=-10.0, high=10.0)
        return self

    @property
    def active(self) -> bool:
        return self.breathing.active or bool(self.trace_csv)

    @property
    def lateral_active(self) -> bool:
        """The phantom moves in x or y (the station needs its lateral joints)."""
        return self.breathing.lateral_active


@dataclass
class SensorFaultConfig:
    """Faults of the force reading that the controllers see (all off by default)."""

    bias_N: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])  # In W, N.
    noise_std_N: float = 0.0  # Extra white noise per axis, N.
    dropout_rate_per_s: float = 0.0  # Dropout starts per second.
    dropout_duration_s: float = 0.05  # Length of one dropout, s.
    dropout_mode: str = "hold"  # "hold" (last value) or "nan".
    spike_rate_per_s: float = 0.0  # Single-tick spikes per second.
    spike_magnitude_N: float = 0.0  # Size of a spike, N.
    extra_latency_s: float = 0.0  # Added delay, s (rounded to control ticks).
    # -1: none; 0, 1, 2: the axis x, y, z that sticks.
    stuck_channel: int = field(
        default=-1, metadata={"allowed": "-1 (none), 0 (x), 1 (y) or 2 (z)"}
    )
    stuck_start_s: float = 0.0  # When it sticks, s.
    # The sensor dies at dead_start_s: a dropout (dropout_mode) that never ends.
    dead: bool = False
    dead_start_s: float = 0.0  # When it dies, s.
    seed: int = 0  # Seed of the noise, spikes and dropouts.

    def __post_init__(self):
        self.validate()

    def validate(self) -> "SensorFaultConfig":
        o = "SensorFaultConfig"
        if not isinstance(self.bias_N, (list, tuple)) or len(self.bias_N) != 3:
            raise VicDrakeError(f"{o}.bias_N must be 3 numbers; got {self.bias_N!r}")
        for i, b in enumerate(self.bias_N):
            check_number(o, f"bias_N[{i}]", b, low=-50.0, high=50.0)
        check_number(o, "noise_std_N", self.noise_std_N, low=0.0, high=20.0)
        check_number(
            o, "dropout_rate_per_s", self.dropout_rate_per_s, low=0.0, high=50.0
        )
        check_number(
            o, "dropout_duration_s", self.dropout_duration_s, low=0.0, high=5.0
        )
        if self.dropout_mode not in DROPOUT_MODES:
            raise VicDrakeError(
                f"{o}.dropout_mode must be one of {list(DROPOUT_MODES)}; "
                f"got {self.dropout_mode!r}"
            )
        check_number(o, "spike_rate_per_s", self.spike_rate_per_s, low=0.0, high=100.0)
        check_number(
            o, "spike_magnitude_N", self.spike_magnitude_N, low=0.0, high=200.0
        )
        check_number(o, "extra_latency_s", self.extra_latency_s, low=0.0, high=0.5)
        if isinstance(self.stuck_channel, bool) or self.stuck_channel not in (
            -1,
            0,
            1,
            2,
        ):
            raise VicDrakeError(
                f"{o}.stuck_channel must be -1 (none), 0, 1 or 2; got {self.stuck_channel!r}"
            )
        check_number(o, "stuck_start_s", self.stuck_start_s, low=0.0)
        if not isinstance(self.dead, bool):
            raise VicDrakeError(f"{o}.dead must be true or false; got {self.dead!r}")
        check_number(o, "dead_start_s", self.dead_start_s, low=0.0)
        _check_int(o, "seed", self.seed, 0)
        return self

    def starting_after(self, duration_s: float) -> list[str]:
        """The timed faults (a stuck channel, a dead sensor) set to start at
        or after ``duration_s``: a run that long never has them. Each as
        "field (value s)"."""
        late = []
        if self.stuck_channel >= 0 and self.stuck_start_s >= duration_s:
            late.append(f"stuck_start_s ({self.stuck_start_s:g} s)")
        if self.dead and self.dead_start_s >= duration_s:
            late.append(f"dead_start_s ({self.dead_start_s:g} s)")
        return late

    @property
    def active(self) -> bool:
        return (
            any(b != 0 for b in self.bias_N)
            or self.noise_std_N > 0
            or (self.dropout_rate_per_s > 0 and self.dropout_duration_s > 0)
            or (self.spike_rate_per_s > 0 and self.spike_magnitude_N > 0)
            or self.extra_latency_s > 0
            or self.stuck_channel >= 0
            or self.dead
        )


@dataclass
class MapErrorConfig:
    """Errors of the map the controller reads (the tissue itself is true)."""

    kappa_scale: float = 1.0  # Map kappa = true kappa x this.
    lam_scale: float = 1.0  # Map lambda = true lambda x this.
    surface_offset_m: float = 0.0  # Map surface = true surface + this, m.
    shift_x_m: float = 0.0  # Map shifted along x by this, m.
    shift_y_m: float = 0.0  # Map shifted along y by this, m.

    def __post_init__(self):
        self.validate()

    def validate(self) -> "MapErrorConfig":
        o = "MapErrorConfig"
        check_number(o, "kappa_scale", self.kappa_scale, low=0.2, high=3.0)
        check_number(o, "lam_scale", self.lam_scale, low=0.2, high=3.0)
        check_number(o, "surface_offset_m", self.surface_offset_m, low=-0.02, high=0.02)
        check_number(o, "shift_x_m", self.shift_x_m, low=-0.05, high=0.05)
        check_number(o, "shift_y_m", self.shift_y_m, low=-0.05, high=0.05)
        return self

    @property
    def active(self) -> bool:
        return (
            self.kappa_scale,
            self.lam_scale,
            self.surface_offset_m,
            self.shift_x_m,
            self.shift_y_m,
        ) != (1.0, 1.0, 0.0, 0.0, 0.0)


@dataclass
class VariationConfig:
    """The scenario's variations (see the module docstring); all off by default."""

    patient: PatientConfig = field(default_factory=PatientConfig)
    motion: PatientMotionConfig = field(default_factory=PatientMotionConfig)
    sensor_faults: SensorFaultConfig = field(default_factory=SensorFaultConfig)
    map_errors: MapErrorConfig = field(default_factory=MapErrorConfig)

    def __post_init__(self):
        self.validate()

    def validate(self) -> "VariationConfig":
        parts = (
            ("patient", PatientConfig),
            ("motion", PatientMotionConfig),
            ("sensor_faults", SensorFaultConfig),
            ("map_errors", MapErrorConfig),
        )
        for name, kind in parts:
            value = getattr(self, name)
            if not isinstance(value, kind):
                raise VicDrakeError(
                    f"VariationConfig.{name} must be a {kind.__name__}; got {value!r}"
                )
            value.validate()
        return self


__all__ = [
    "LATERAL_BREATHING_MAX_M",
    "BreathingConfig",
    "MapErrorConfig",
    "PatientConfig",
    "PatientMotionConfig",
    "SensorFaultConfig",
    "VariationConfig",
]
