"""StationParams: everything the simulated rig is made of (SI units).

The plant's own settings are Drake's ``MultibodyPlantConfig`` (field
``plant``); the rest are the UR3e's joint servo, the F/T sensor, the
indenter, the phantom and the tissue force. Defaults are the paper's rig.

The dataclass is mutable on purpose: Drake's ``yaml_load_typed`` fills a
default-constructed instance field by field. Validation therefore runs in
``__post_init__`` (direct construction) and in :meth:`StationParams.validate`,
which :func:`vic_drake.station.MakeStation` calls again on what it is given.
Every message names the field and the value.

(No ``from __future__ import annotations`` here: Drake's YAML loader reads
the field types at run time.)
"""

from dataclasses import dataclass, field, fields, replace

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlantConfig

from vic_drake.errors import VicDrakeError
from vic_drake.paper import GRAVITY_M_PER_S2
from vic_drake.tissue.relaxation import (
    TISSUE_LAWS,
    RelaxationParams,
    tissue_relaxation,
)

#: Largest shift of the phantom from its place on each axis, m: more moves
#: it off the scan, or is a length typed in mm.
MAX_PHANTOM_OFFSET_M = 0.1

#: Drake's discrete contact solvers the station supports.
CONTACT_APPROXIMATIONS = ("sap", "lagged")


def default_plant_config() -> MultibodyPlantConfig:
    """The station's plant: 2 ms steps, SAP, hydroelastic contact with fallback.

    The step is the command and sensor period, so every plant step meets one
    controller tick; see docs/decisions.md, "Plant step".
    """
    return MultibodyPlantConfig(
        time_step=0.002,
        discrete_contact_approximation="sap",
        contact_model="hydroelastic_with_fallback",
    )


def _plant_config_values(config: MultibodyPlantConfig) -> dict:
    """The fields of a MultibodyPlantConfig as a dict (for ==, copies, pickling)."""
    return {f.name: getattr(config, f.name) for f in MultibodyPlantConfig.__fields__}


def _vec(value, n, name):
    a = np.asarray(value, float)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise VicDrakeError(
            f"StationParams.{name} must be {n} finite numbers, got {value!r}"
        )
    return a


@dataclass
class StationParams:
    """Everything the simulated rig is made of (SI units).

    Defaults: the UR3e and tool of the paper's rig; the sensor noise is
    estimated from the free-air samples of the real logs (see
    docs/decisions.md, "Sensor noise").

    Sensor lag: none by default, although the logs show the force trailing
    the logged pose; see docs/decisions.md, "Sensor lag". Set
    ``sensor_lag_samples`` to study a lagging sensor.
    """

    # -- plant ---------------------------------------------------------------
    # Drake's plant settings: time_step (discrete step, s, > 0),
    # discrete_contact_approximation ("sap" or "lagged"), contact_model, ...
    plant: MultibodyPlantConfig = field(default_factory=default_plant_config)
    # Gravity magnitude (along -z of W), m/s^2.
    gravity_m_per_s2: float = GRAVITY_M_PER_S2
    # -- UR3e joint position servo (implicit PD actuators) ---------------------
    # Stiffness per joint, N m/rad. The servo's integral action removes the
    # static error a tip load leaves with the gravity feed-forward alone; see
    # docs/decisions.md, "Joint servo".
    joint_kp_Nm_per_rad: list[float] = field(
        default_factory=lambda: [8000.0, 8000.0, 4000.0, 1000.0, 1000.0, 1000.0]
    )
    # Damping per joint, N m s/rad (about critical for the arm's inertia).
    joint_kd_Nms_per_rad: list[float] = field(
        default_factory=lambda: [120.0, 120.0, 60.0, 8.0, 8.0, 8.0]
    )
    command_period_s: float = 0.002  # Period of the position command (500 Hz), s.
    # Time constant of the command smoothing, s: the UR driver's servoj
    # lookahead_time (0.03 s); the arm tracks commands with this lag.
    servo_time_constant_s: float = 0.03
    # Integral time of the servo's tracking-error integral, s (0 = none):
    # removes the static error a load would leave with the PD alone.
    servo_integral_time_s: float = 0.05
    # -- BOTA SensONE F/T sensor ---------------------------------------------
    ft_mount_mass_kg: float = 0.149  # Mounting-side mass, kg.
    ft_wrench_mass_kg: float = 0.081  # Wrench-side mass, kg.
    ft_wrench_offset_m: float = (
        0.035  # Wrench frame S from the mounting face along z, m.
    )
    ft_radius_m: float = 0.04  # Housing radius (geometry and inertia), m.
    sensor_period_s: float = 0.002  # Sampling period, s (500 Hz).
    sensor_lag_samples: int = 0  # Reading delay, samples (0: see the class doc).
    # Noise std of the force components (x, y, z) in S, N (nearly white).
    sensor_noise_std_N: list[float] = field(
        default_factory=lambda: [0.055, 0.055, 0.045]
    )
    sensor_torque_noise_std_Nm: float = 0.0  # Torque noise std, N m (not in the logs).
    # Force bias in S, N.
    sensor_bias_N: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    # -- indenter (3D-printed rigid cone with a spherical tip) -----------------
    indenter_mass_kg: float = 0.04  # Mass, kg (PLA, about 30 cm^3).
    indenter_length_m: float = 0.07  # Probe tip from the wrench frame along z, m.
    indenter_tip_radius_m: float = 0.02  # Radius of the spherical tip, m.
    # -- phantom ----------------------------------------------------------------
    # Map frame in W at zero lift, m.
    phantom_offset_m: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    phantom_mass_kg: float = 5.0  # Mass of the lifted phantom, kg.
    # Lift servo stiffness, N/m (stiff: the phantom barely sinks under the
    # probe; see docs/decisions.md, "Phantom lift servo").
    phantom_kp_N_per_m: float = 2.0e6
    phantom_kd_Ns_per_m: float = 6.0e3  # Lift servo damping, N s/m (about critical).
    phantom_mesh_resolution_m: float = 0.015  # Grid spacing of the contact mesh, m.
    phantom_thickness_m: float = 0.05  # Slab below the lowest surface point, m.
    hydroelastic_modulus_Pa: float = 1.0e5  # Phantom's hydroelastic modulus, Pa.
    hydroelastic_resolution_hint_m: float = (
        0.03  # Tessellation of rigid link shapes, m.
    )
    hunt_crossley_dissipation_s_per_m: float = 5.0  # Drake contact dissipation, s/m.
    friction_coefficient: float = 0.5  # Coulomb friction of the safety contact.
    robot_contact: bool = True  # Robot links and sensor collide with the phantom.
    # Sliding friction of the tissue on the tip (times the HC force; 0 = the
    # paper's 1-D model), identified from the real VS scans' lateral sensor
    # forces; see docs/decisions.md, "Tissue friction and normal".
    tissue_friction_coefficient: float = 0.25
    # Regularisation speed of that friction, m/s.
    tissue_slip_speed_m_per_s: float = 0.005
    # Tissue force along the surface normal (True) or vertical (False, the
    # paper's 1-D model); the real scans' lateral forces follow the normal
    # (docs/decisions.md, "Tissue friction and normal").
    tissue_force_along_normal: bool = True
    # Tissue law of the force element: "relaxing" (Hunt-Crossley whose elastic
    # term relaxes, vic_drake.tissue.DEFAULT_RELAXATION; the map's kappa is
    # the instantaneous modulus) or "hc" (plain Hunt-Crossley); see
    # docs/decisions.md, "Tissue relaxation".
    tissue_law: str = "relaxing"
    # Branches of the "relaxing" law, to study another relaxation: fractions
    # g_i and time constants tau_i (s), one of each per branch. Both empty
    # (the default): vic_drake.tissue.DEFAULT_RELAXATION. Not with "hc".
    tissue_relaxation_fractions: list[float] = field(default_factory=list)
    tissue_relaxation_time_constants_s: list[float] = field(default_factory=list)
    # Grid of the force element's per-step lookup of non-grid phantoms, m
    # (a GridPhantom is looked up on its own grid).
    tissue_lookup_resolution_m: float = 0.0005

    def __post_init__(self):
        self.validate()

    def validate(self) -> "StationParams":
        """Checks every field; raises VicDrakeError naming the bad one. Returns self."""
        self._validate_plant()
        positive = (
            "gravity_m_per_s2",
            "command_period_s",
            "servo_time_constant_s",
            "ft_mount_mass_kg",
            "ft_wrench_mass_kg",
            "ft_wrench_offset_m",
            "ft_radius_m",
            "sensor_period_s",
            "indenter_mass_kg",
            "indenter_length_m",
            "indenter_tip_radius_m",
            "phantom_mass_kg",
            "phantom_kp_N_per_m",
            "phantom_mesh_resolution_m",
            "phantom_thickness_m",
            "hydroelastic_modulus_Pa",
            "hydroelastic_resolution_hint_m",
            "tissue_lookup_resolution_m",
            "tissue_slip_speed_m_per_s",
        )
        for name in positive:
            value = getattr(self, name)
            if not (
                isinstance(value, (int, float)) and np.isfinite(value) and value > 0
            ):
                raise VicDrakeError(
                    f"StationParams.{name} must be a number > 0, got {value!r}"
                )
        nonneg = (
            "servo_integral_time_s",
            "sensor_torque_noise_std_Nm",
            "phantom_kd_Ns_per_m",
            "hunt_crossley_dissipation_s_per_m",
            "friction_coefficient",
            "tissue_friction_coefficient",
        )
        for name in nonneg:
            value = getattr(self, name)
            if not (
                isinstance(value, (int, float)) and np.isfinite(value) and value >= 0
            ):
                raise VicDrakeError(
                    f"StationParams.{name} must be a number >= 0, got {value!r}"
                )
        kp = _vec(self.joint_kp_Nm_per_rad, 6, "joint_kp_Nm_per_rad")
        kd = _vec(self.joint_kd_Nms_per_rad, 6, "joint_kd_Nms_per_rad")
        if np.any(kp <= 0) or np.any(kd < 0):
            raise VicDrakeError(
                "StationParams.joint_kp_Nm_per_rad must be > 0 and joint_kd_Nms_per_rad >= 0, "
                f"got {self.joint_kp_Nm_per_rad!r}, {self.joint_kd_Nms_per_rad!r}"
            )
        noise = _vec(self.sensor_noise_std_N, 3, "sensor_noise_std_N")
        if np.any(noise < 0):
            raise VicDrakeError(
                f"StationParams.sensor_noise_std_N must be >= 0, got {self.sensor_noise_std_N!r}"
            )
        _vec(self.sensor_bias_N, 3, "sensor_bias_N")
        offset = _vec(self.phantom_offset_m, 3, "phantom_offset_m")
        if np.any(np.abs(offset) > MAX_PHANTOM_OFFSET_M):  # E.g. 10 (mm) for 0.01.
            raise VicDrakeError(
                "StationParams.phantom_offset_m is in metres, each at most "
                f"{MAX_PHANTOM_OFFSET_M:g} m in size; got {self.phantom_offset_m!r} "
                "(0.01 is 1 cm)"
            )
        lag = self.sensor_lag_samples
        if isinstance(lag, bool) or not isinstance(lag, (int, np.integer)) or lag < 0:
            raise VicDrakeError(
                f"StationParams.sensor_lag_samples must be an integer >= 0, got {lag!r}"
            )
        if self.indenter_tip_radius_m >= self.indenter_length_m:
            raise VicDrakeError(
                f"StationParams.indenter_tip_radius_m ({self.indenter_tip_radius_m}) must be "
                f"< indenter_length_m ({self.indenter_length_m})"
            )
        if self.tissue_law not in TISSUE_LAWS:
            raise VicDrakeError(
                f"StationParams.tissue_law must be one of {TISSUE_LAWS}, got "
                f"{self.tissue_law!r}"
            )
        self._validate_relaxation()
        for name in ("robot_contact", "tissue_force_along_normal"):
            if not isinstance(getattr(self, name), bool):
                raise VicDrakeError(
                    f"StationParams.{name} must be a bool, got {getattr(self, name)!r}"
                )
        return self

    def _validate_relaxation(self) -> None:
        g = self.tissue_relaxation_fractions
        tau = self.tissue_relaxation_time_constants_s
        for name, values in (
            ("tissue_relaxation_fractions", g),
            ("tissue_relaxation_time_constants_s", tau),
        ):
            if not isinstance(values, (list, tuple)) or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in values
            ):
                raise VicDrakeError(
                    f"StationParams.{name} must be a list of numbers, got {values!r}"
                )
        if len(g) != len(tau):
            raise VicDrakeError(
                "StationParams.tissue_relaxation_fractions and "
                "tissue_relaxation_time_constants_s must have one value per branch, "
                f"got {list(g)!r} and {list(tau)!r}"
            )
        if not g:
            return
        if self.tissue_law != "relaxing":
            raise VicDrakeError(
                "StationParams.tissue_relaxation_fractions / _time_constants_s are "
                f"given ({list(g)!r}, {list(tau)!r}) but tissue_law is "
                f"{self.tissue_law!r}; they need tissue_law 'relaxing'"
            )
        # The values' rules are RelaxationParams's; its message, renamed.
        try:
            RelaxationParams(tuple(g), tuple(tau))
        except VicDrakeError as err:
            message = str(err).replace(
                "RelaxationParams.fractions",
                "StationParams.tissue_relaxation_fractions",
            )
            message = message.replace(
                "RelaxationParams.time_constants_s",
                "StationParams.tissue_relaxation_time_constants_s",
            )
            raise VicDrakeError(message) from None

    def with_relaxation(self, relaxation: RelaxationParams) -> "StationParams":
        """A copy whose relaxing tissue has ``relaxation``'s branches."""
        return replace(
            self,
            tissue_relaxation_fractions=list(relaxation.fractions),
            tissue_relaxation_time_constants_s=list(relaxation.time_constants_s),
        )

    @property
    def relaxation(self) -> RelaxationParams | None:
        """The tissue element's relaxation: None for plain HC ("hc"); the
        given branches, else :data:`vic_drake.tissue.DEFAULT_RELAXATION`."""
        if self.tissue_law == "relaxing" and self.tissue_relaxation_fractions:
            return RelaxationParams(
                tuple(self.tissue_relaxation_fractions),
                tuple(self.tissue_relaxation_time_constants_s),
            )
        return tissue_relaxation(self.tissue_law)

    def _validate_plant(self) -> None:
        config = self.plant
        if not isinstance(config, MultibodyPlantConfig):
            raise VicDrakeError(
                "StationParams.plant must be a pydrake MultibodyPlantConfig, got "
                f"{type(config).__name__}"
            )
        step = config.time_step
        if not (np.isfinite(step) and step > 0):
            raise VicDrakeError(
                f"StationParams.plant.time_step must be a number > 0 (a discrete "
                f"plant), got {step!r}"
            )
        if config.discrete_contact_approximation not in CONTACT_APPROXIMATIONS:
            raise VicDrakeError(
                "StationParams.plant.discrete_contact_approximation must be 'sap' or "
                f"'lagged', got {config.discrete_contact_approximation!r}"
            )

    # MultibodyPlantConfig has neither == nor pickling: compare and pickle its
    # fields (scenarios are compared after a YAML round trip and sent to
    # worker processes).
    def __eq__(self, other):
        if other.__class__ is not self.__class__:
            return NotImplemented
        for f in fields(self):
            a, b = getattr(self, f.name), getattr(other, f.name)
            if isinstance(a, MultibodyPlantConfig) and isinstance(
                b, MultibodyPlantConfig
            ):
                a, b = _plant_config_values(a), _plant_config_values(b)
            if a != b:
                return False
        return True

    __hash__ = None  # Mutable, as a dataclass with eq.

    def __getstate__(self):
        state = dict(self.__dict__)
        if isinstance(self.plant, MultibodyPlantConfig):
            state["plant"] = _plant_config_values(self.plant)
        return state

    def __setstate__(self, state):
        state = dict(state)
        if isinstance(state.get("plant"), dict):
            state["plant"] = MultibodyPlantConfig(**state["plant"])
        self.__dict__.update(state)

    # Tool geometry used by several builders.
    @property
    def X_W3M(self) -> RigidTransform:
        """Pose of the sensor mounting frame M in wrist_3_link."""
        return RigidTransform(RotationMatrix.MakeZRotation(-np.pi / 2), np.zeros(3))

    @property
    def p_MP(self) -> np.ndarray:
        """Probe tip P from the mounting frame M, in M, m."""
        return np.array([0.0, 0.0, self.ft_wrench_offset_m + self.indenter_length_m])

    @property
    def distal_mass_kg(self) -> float:
        """Mass the sensor carries (wrench side + indenter), kg."""
        return self.ft_wrench_mass_kg + self.indenter_mass_kg


__all__ = ["CONTACT_APPROXIMATIONS", "StationParams", "default_plant_config"]
