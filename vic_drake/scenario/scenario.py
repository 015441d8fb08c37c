"""The Scenario: the whole configuration of one closed-loop scan.

A :class:`Scenario` is a tree of mutable dataclasses (phantom, station,
controller, FDCC, reference trajectory, phantom-lift disturbance, logging,
simulator, seed, duration) that Drake's ``yaml_load_typed`` fills field by
field (:mod:`vic_drake.scenario.io`). Every field carries its unit in its
name or comment; every invariant is checked in ``__post_init__`` and again in
:meth:`Scenario.validate`, which the loader calls on what it loaded, with
messages that name the field and the bad value.

The default scenario, ``Scenario()``, is a VS-VF scan on the synthetic
phantom in the paper's pattern: the target comes down from above to z =
0.085 m at 1 cm/s, moves along -x at 1 cm/s for 20 cm, then jumps up
(lift-off), as the real logs do. The shipped paper scans
(``diagrams/nominal_vs_vf_synthetic.yaml`` and its siblings, or
:func:`vic_drake.experiments.paper_scenarios.synthetic_scenario`) differ in
details such as the height the target comes down from (0.12 m there).
"""

from dataclasses import dataclass, field

from pydrake.systems.analysis import GetIntegrationSchemes, SimulatorConfig

from vic_drake.control.fdcc import FdccParams
from vic_drake.control.params import (
    ControllerParams,
    ReferenceParams,
    StiffnessQpParams,
)
from vic_drake.control.watchdog import SensorWatchdogParams
from vic_drake.errors import VicDrakeError, check_known_attributes, check_number
from vic_drake.estimation.online import OnlineEstimatorParams
from vic_drake.scenario.disturbance import DisturbanceConfig
from vic_drake.scenario.logging import LoggingConfig
from vic_drake.scenario.phantom import PhantomConfig
from vic_drake.scenario.plain import as_plain
from vic_drake.scenario.trajectory import TrajectoryConfig
from vic_drake.scenario.variation import VariationConfig
from vic_drake.station.params import StationParams

#: The stiffness QP solver of the scans: the closed-form solver (the same K
#: as OSQP's, and cheaper per tick; see docs/decisions.md, "Scan QP solver",
#: and :class:`vic_drake.control.params.StiffnessQpParams`). Set
#: ``controller.qp.solver: osqp`` in a scenario to run Drake's
#: MathematicalProgram instead.
SCAN_QP_SOLVER = "exact"

#: Where the controller reads the probe's position and velocity.
CONTROLLER_FEEDBACKS = ("measured", "command")

#: Where the VS controllers take kappa, lambda and the surface from: the
#: tissue map, or the online estimator (no map; seeded with a prior).
STIFFNESS_SOURCES = ("map", "online")


def _online_estimator() -> OnlineEstimatorParams:
    """The closed loop's estimator: the EKF with a surface state (no map surface)."""
    return OnlineEstimatorParams(method="ekf", surface_walk_m_per_sqrt_s=0.001)


def _vs_vf_controller() -> ControllerParams:
    """VS-VF as on the real rig (test_nardi_matForce_lowR: R = 1e-5)."""
    return ControllerParams(
        qp=StiffnessQpParams(r_weight=[1e-5, 1e-5, 1e-5], solver=SCAN_QP_SOLVER),
        reference=ReferenceParams(controller="vs-vf"),
    )


def _validate_part(owner: str, name: str, value, kind: type) -> None:
    """Checks that a nested config has its type, then runs its own checks."""
    if not isinstance(value, kind):
        raise VicDrakeError(f"{owner}.{name} must be a {kind.__name__}; got {value!r}")
    validate = getattr(value, "validate", None)
    if callable(validate):
        validate()
    else:
        # A config without validate() checks itself in __post_init__ only;
        # run that again on the values the loader wrote into it.
        post_init = getattr(value, "__post_init__", None)
        if callable(post_init):
            post_init()


def _validate_simulator(owner: str, config: SimulatorConfig) -> None:
    schemes = GetIntegrationSchemes()
    if config.integration_scheme not in schemes:
        raise VicDrakeError(
            f"{owner}.simulator.integration_scheme must be one of {schemes}; "
            f"got {config.integration_scheme!r}"
        )
    check_number(
        f"{owner}.simulator",
        "max_step_size",
        config.max_step_size,
        low=0.0,
        low_open=True,
    )
    check_number(
        f"{owner}.simulator", "accuracy", config.accuracy, low=0.0, low_open=True
    )
    check_number(
        f"{owner}.simulator",
        "target_realtime_rate",
        config.target_realtime_rate,
        low=0.0,
    )
    if config.start_time != 0.0:
        # The target, the disturbance and the logs are timed from t = 0.
        raise VicDrakeError(
            f"{owner}.simulator.start_time must be 0 (a scan starts at t = 0); "
            f"got {config.start_time!r}"
        )


def _validate_slope(owner: str, s) -> None:
    """The online surface from the slope needs the tip kept moving."""
    if (
        s.stiffness_source == "online"
        and s.online_estimator.surface_from_slope
        and s.controller.reference.penetration_dither_m == 0.0
    ):
        raise VicDrakeError(
            f"{owner}.online_estimator.surface_from_slope needs the reference's "
            "dither (controller.reference.penetration_dither_m > 0): at a steady "
            "depth the tip does not move and the slope is not observable; got "
            "penetration_dither_m 0.0"
        )


@dataclass
class Scenario:
    """One closed-loop scan: phantom, station, controller, FDCC, references.

    Equality compares the plain forms (:func:`vic_drake.scenario.plain.as_plain`):
    Drake's bound configs have no ``==`` and tuples equal lists of the same
    items. Pickling sends the simulator config as its fields.

    Attributes:
        name: label of the run (used in reports and file names).
        description: free text (which paper figure or real log it mirrors).
        phantom: the tissue.
        station: the UR3e + F/T sensor + probe + phantom plant
            (default StationParams(): no sensor lag in the loop, see there).
        controller: the variable impedance controller (tank, QP, reference).
        fdcc: the forward-dynamics compliance controller that turns
            stiffness and target force into joint position commands
            (default FdccParams(): pose error on the measured joints).
        watchdog: the force sensor's watchdog in the compliance stage (on by
            default: a stuck force channel stops the scan and lifts the
            probe; see :mod:`vic_drake.control.watchdog`).
        trajectory: the target x_d(t).
        disturbance: the phantom lift z_offset(t).
        logging: recording period.
        simulator: Drake's simulator settings (integrator, real-time rate),
            applied with ``ApplySimulatorConfig``. The scan diagram is purely
            discrete, so the integrator settings do not change its result.
        controller_feedback: "measured" or "command" (see the field).
        seed: seed of every random element of the diagram (sensor noise).
        duration_s: simulated time, s; None means trajectory end + 1 s.
    """

    name: str = "vs_vf_nominal_synthetic"
    description: str = ""
    phantom: PhantomConfig = field(default_factory=PhantomConfig)
    station: StationParams = field(default_factory=StationParams)
    controller: ControllerParams = field(default_factory=_vs_vf_controller)
    fdcc: FdccParams = field(default_factory=FdccParams)
    # The force sensor's watchdog: a channel stuck while the others change
    # stops the scan and lifts the probe (enabled: false turns it off).
    watchdog: SensorWatchdogParams = field(default_factory=SensorWatchdogParams)
    trajectory: TrajectoryConfig = field(default_factory=TrajectoryConfig)
    disturbance: DisturbanceConfig = field(default_factory=DisturbanceConfig)
    logging: LoggingConfig = field(default_factory=LoggingConfig)
    simulator: SimulatorConfig = field(default_factory=SimulatorConfig)
    # Where the controller reads the probe's position and velocity: "measured"
    # (the station's probe) or "command" (forward kinematics of the FDCC's
    # joint command, what FZI's controller on a position interface sees).
    controller_feedback: str = "measured"
    seed: int = 0  # Seed of the random elements (sensor noise), >= 0.
    duration_s: float | None = None  # Simulated time, s (None: trajectory end + 1 s).
    # Patient, motion, sensor faults, map errors (all off by default; see
    # vic_drake.scenario.variation).
    variations: VariationConfig = field(default_factory=VariationConfig)
    # Where kappa, lambda and the surface of the force references and the
    # stiffness QP come from: "map" (the phantom's map, with its errors) or
    # "online" (online_estimator, seeded with its prior; no map read).
    stiffness_source: str = "map"
    online_estimator: OnlineEstimatorParams = field(default_factory=_online_estimator)
    # With "online": where the estimator's surface comes from, "estimated"
    # (latched at first contact, no map at all) or "map" (the map's surface
    # under the probe; kappa and lambda still online).
    online_surface: str = "estimated"

    def __post_init__(self):
        self.validate()

    def validate(self) -> "Scenario":
        """Checks every field and every nested config; returns self.

        Raises:
            VicDrakeError: naming the field and the bad value.
        """
        o = "Scenario"
        check_known_attributes(self, o)
        if not isinstance(self.name, str) or not self.name:
            raise VicDrakeError(
                f"{o}.name must be a non-empty string; got {self.name!r}"
            )
        parts = (
            ("phantom", PhantomConfig),
            ("station", StationParams),
            ("controller", ControllerParams),
            ("fdcc", FdccParams),
            ("watchdog", SensorWatchdogParams),
            ("trajectory", TrajectoryConfig),
            ("disturbance", DisturbanceConfig),
            ("logging", LoggingConfig),
            ("variations", VariationConfig),
            ("online_estimator", OnlineEstimatorParams),
        )
        for name, kind in parts:
            _validate_part(o, name, getattr(self, name), kind)
        if not isinstance(self.simulator, SimulatorConfig):
            raise VicDrakeError(
                f"{o}.simulator must be a SimulatorConfig; got {self.simulator!r}"
            )
        _validate_simulator(o, self.simulator)
        if self.online_surface not in ("estimated", "map"):
            raise VicDrakeError(
                f"{o}.online_surface must be 'estimated' or 'map'; "
                f"got {self.online_surface!r}"
            )
        if self.stiffness_source not in STIFFNESS_SOURCES:
            raise VicDrakeError(
                f"{o}.stiffness_source must be one of {list(STIFFNESS_SOURCES)}; "
                f"got {self.stiffness_source!r}"
            )
        controller = self.controller.reference.controller
        if self.stiffness_source == "online" and not controller.startswith("vs"):
            raise VicDrakeError(
                f"{o}.stiffness_source 'online' is for the variable-stiffness "
                f"controllers (vs-cf, vs-vf), whose references use kappa and "
                f"lambda; {controller} does not read them: use stiffness_source "
                "'map' with it"
            )
        _validate_slope(o, self)
        if self.controller_feedback not in CONTROLLER_FEEDBACKS:
            raise VicDrakeError(
                f"{o}.controller_feedback must be 'measured' or 'command'; "
                f"got {self.controller_feedback!r}"
            )
        if (
            isinstance(self.seed, bool)
            or not isinstance(self.seed, int)
            or self.seed < 0
        ):
            raise VicDrakeError(f"{o}.seed must be an integer >= 0; got {self.seed!r}")
        if self.duration_s is not None:
            check_number(o, "duration_s", self.duration_s, low=0.0, low_open=True)
        period = self.station.sensor_period_s
        if self.watchdog.enabled and self.watchdog.dead_window_s < 2 * period:
            raise VicDrakeError(
                f"{o}.watchdog.dead_window_s ({self.watchdog.dead_window_s:g} s) "
                f"must be at least twice station.sensor_period_s ({period:g} s): "
                "a live sensor at that rate repeats each reading for a period; "
                "raise dead_window_s (or set watchdog.enabled: false)"
            )
        if self.variations.patient.enabled and self.phantom.kind != "synthetic":
            raise VicDrakeError(
                f"{o}.variations.patient needs phantom.kind 'synthetic' (a "
                f"patient is a synthetic chest); got {self.phantom.kind!r}"
            )
        return self

    def __eq__(self, other):
        if not isinstance(other, Scenario):
            return NotImplemented
        return as_plain(self) == as_plain(other)

    __hash__ = None  # Mutable, as a dataclass with eq.

    # SimulatorConfig cannot be pickled: pickle its fields (scenarios are
    # sent to worker processes).
    def __getstate__(self):
        state = dict(self.__dict__)
        if isinstance(self.simulator, SimulatorConfig):
            state["simulator"] = as_plain(self.simulator)
        return state

    def __setstate__(self, state):
        state = dict(state)
        if isinstance(state.get("simulator"), dict):
            state["simulator"] = SimulatorConfig(**state["simulator"])
        self.__dict__.update(state)

    @property
    def total_duration_s(self) -> float:
        """The simulated time of a full run, s."""
        if self.duration_s is not None:
            return float(self.duration_s)
        return self.trajectory.end_time_s + 1.0
