"""The typed scenario of a scan: everything one closed-loop run needs.

A :class:`Scenario` is a tree of dataclasses (phantom, station, controller,
FDCC, reference trajectory, phantom-lift disturbance, logging, seed,
duration). Every field carries its unit in its name or comment and every
invariant is checked in ``__post_init__`` with a message naming the field
and the bad value. Scenarios are stored as YAML in ``diagrams/`` and loaded
with Drake's ``yaml_load_typed`` (:func:`load_scenario`); every run can store
the exact configuration it ran with (:func:`save_scenario`).

Drake's YAML loader fills a default-constructed object field by field and
reads the field types from the dataclass. The parameter classes of the other
areas use ``from __future__ import annotations`` (string annotations, which
the loader cannot read) and some may be frozen. So the loader works on a
*mutable twin* of the schema (same field names, resolved types, tuples as
lists, no validation), and the loaded twin is then rebuilt into the real
classes by calling their constructors, which runs every ``__post_init__``
check on the loaded values.

The default scenario is the paper's VS-VF nominal scan on the synthetic
phantom: the target comes down from above to z = 0.085 m at 1 cm/s, moves
along -x at 1 cm/s for 20 cm, then jumps up (lift-off), as the real logs do.
"""

from __future__ import annotations

import dataclasses
import math
import os
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path

from vic_drake.control.fdcc import FdccParams
from vic_drake.control.params import (
    ControllerParams,
    ReferenceParams,
    StiffnessQpParams,
)
from vic_drake.errors import VicDrakeError
from vic_drake.station import StationParams
from vic_drake.tissue.phantom import PHANTOM_KINDS


def _number(
    owner: str, name: str, value, *, low=None, low_open=False, high=None
) -> float:
    """Checks one scalar field; returns it as float or raises naming it."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise VicDrakeError(f"{owner}.{name} must be a number; got {value!r}") from None
    if not math.isfinite(v):
        raise VicDrakeError(f"{owner}.{name} must be finite; got {value!r}")
    if low is not None and (v <= low if low_open else v < low):
        op = ">" if low_open else ">="
        raise VicDrakeError(f"{owner}.{name} must be {op} {low}; got {value!r}")
    if high is not None and v > high:
        raise VicDrakeError(f"{owner}.{name} must be <= {high}; got {value!r}")
    return v


@dataclass
class PhantomConfig:
    """Which tissue the probe scans.

    Attributes:
        kind: "synthetic" (the analytic chest, always available) or
            "measured" (the paper's GP map from ``<data>/phantom_map``).
        lookup: how the *tissue* (the station's force element) reads the
            measured map: "bilinear" (a smooth body) or "nearest".
        controller_lookup: how the *controller* reads the map (surface,
            kappa, lambda for its references): "nearest", what the real
            controller did, or "bilinear".
    """

    kind: str = "synthetic"  # "synthetic" | "measured".
    lookup: str = "bilinear"  # Tissue lookup on the measured map.
    controller_lookup: str = "nearest"  # The controller's lookup on the measured map.

    def __post_init__(self):
        if self.kind not in PHANTOM_KINDS:
            raise VicDrakeError(
                f"PhantomConfig.kind must be one of {list(PHANTOM_KINDS)}; got {self.kind!r}"
            )
        for name in ("lookup", "controller_lookup"):
            value = getattr(self, name)
            if value not in ("bilinear", "nearest"):
                raise VicDrakeError(
                    f"PhantomConfig.{name} must be 'bilinear' or 'nearest'; got {value!r}"
                )


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
        o = "TrajectoryConfig"
        for name in ("start_x_m", "end_x_m", "y_m", "approach_z_m", "target_z_m"):
            _number(o, name, getattr(self, name))
        for name in (
            "start_delay_s",
            "dwell_s",
            "end_dwell_s",
            "liftoff_height_m",
            "liftoff_s",
        ):
            _number(o, name, getattr(self, name), low=0.0)
        for name in ("approach_speed_m_per_s", "scan_speed_m_per_s"):
            _number(o, name, getattr(self, name), low=0.0, low_open=True)
        if self.approach_z_m < self.target_z_m:
            raise VicDrakeError(
                f"{o}.approach_z_m ({self.approach_z_m!r}) must be >= target_z_m "
                f"({self.target_z_m!r}): the target approaches from above"
            )
        if self.initial_tip_z_m is not None:
            _number(o, "initial_tip_z_m", self.initial_tip_z_m)
        if self.waypoints:
            rows = [list(r) for r in self.waypoints]
            for i, r in enumerate(rows):
                if len(r) != 4:
                    raise VicDrakeError(
                        f"{o}.waypoints[{i}] must be [t_s, x_m, y_m, z_m]; got {r!r}"
                    )
                for j, v in enumerate(r):
                    _number(o, f"waypoints[{i}][{j}]", v)
            if len(rows) < 2:
                raise VicDrakeError(
                    f"{o}.waypoints needs at least 2 rows; got {len(rows)}"
                )
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
        o = "PhantomLift"
        _number(o, "start_s", self.start_s, low=0.0)
        _number(o, "height_m", self.height_m, low=-0.1, high=0.1)
        _number(o, "rise_s", self.rise_s, low=0.0, low_open=True)
        _number(o, "hold_s", self.hold_s, low=0.0)
        _number(o, "fall_s", self.fall_s, low=0.0, low_open=True)


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
        o = "DisturbanceConfig"
        for i, lift in enumerate(self.lifts):
            if not isinstance(lift, PhantomLift):
                raise VicDrakeError(
                    f"{o}.lifts[{i}] must be a PhantomLift; got {lift!r}"
                )
        if self.lifts and self.table:
            raise VicDrakeError(f"{o}: give either lifts or table, not both")
        prev = -math.inf
        for i, row in enumerate(self.table):
            if len(row) != 2:
                raise VicDrakeError(
                    f"{o}.table[{i}] must be [t_s, z_offset_m]; got {row!r}"
                )
            t = _number(o, f"table[{i}][0]", row[0])
            _number(o, f"table[{i}][1]", row[1], low=-0.1, high=0.1)
            if not t > prev:
                raise VicDrakeError(
                    f"{o}.table times must increase; row {i} has t = {t!r}"
                )
            prev = t

    @property
    def is_nominal(self) -> bool:
        return not self.lifts and not self.table


@dataclass
class LoggingConfig:
    """What is recorded."""

    period_s: float = 0.002  # Sampling period of the loggers, s (real logs: 500 Hz).

    def __post_init__(self):
        _number("LoggingConfig", "period_s", self.period_s, low=0.0, low_open=True)


#: The stiffness QP solver of the scans: the closed-form solver (the same K
#: as OSQP's within 1e-9 N/m on the real logs, about 10x cheaper per tick;
#: see :class:`vic_drake.control.params.StiffnessQpParams`). Set
#: ``controller.qp.solver: osqp`` in a scenario to run Drake's
#: MathematicalProgram instead.
SCAN_QP_SOLVER = "exact"


def _vs_vf_controller() -> ControllerParams:
    """VS-VF as on the real rig (test_nardi_matForce_lowR: R = 1e-5)."""
    return ControllerParams(
        qp=StiffnessQpParams(r_weight=[1e-5, 1e-5, 1e-5], solver=SCAN_QP_SOLVER),
        reference=ReferenceParams(controller="vs-vf"),
    )


@dataclass
class Scenario:
    """One closed-loop scan: phantom, station, controller, FDCC, references.

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
        trajectory: the target x_d(t).
        disturbance: the phantom lift z_offset(t).
        logging: recording period.
        controller_feedback: "measured" or "command" (see the field).
        seed: seed of every random element of the diagram (sensor noise).
        duration_s: simulated time, s; None means trajectory end + 1 s.
    """

    name: str = "vs_vf_nominal_synthetic"
    description: str = ""
    phantom: PhantomConfig = field(default_factory=PhantomConfig)
    station: StationParams = field(default_factory=StationParams)
    controller: ControllerParams = field(default_factory=lambda: _vs_vf_controller())
    fdcc: FdccParams = field(default_factory=FdccParams)
    trajectory: TrajectoryConfig = field(default_factory=TrajectoryConfig)
    disturbance: DisturbanceConfig = field(default_factory=DisturbanceConfig)
    logging: LoggingConfig = field(default_factory=LoggingConfig)
    # Where the controller reads the probe's position and velocity: "measured"
    # (the station's probe) or "command" (forward kinematics of the FDCC's
    # joint command, what FZI's controller on a position interface sees).
    controller_feedback: str = "measured"
    seed: int = 0  # Seed of the random elements (sensor noise), >= 0.
    duration_s: float | None = None  # Simulated time, s (None: trajectory end + 1 s).

    def __post_init__(self):
        o = "Scenario"
        if not isinstance(self.name, str) or not self.name:
            raise VicDrakeError(
                f"{o}.name must be a non-empty string; got {self.name!r}"
            )
        checks = (
            ("phantom", PhantomConfig),
            ("station", StationParams),
            ("controller", ControllerParams),
            ("fdcc", FdccParams),
            ("trajectory", TrajectoryConfig),
            ("disturbance", DisturbanceConfig),
            ("logging", LoggingConfig),
        )
        for name, kind in checks:
            value = getattr(self, name)
            if not isinstance(value, kind):
                raise VicDrakeError(
                    f"{o}.{name} must be a {kind.__name__}; got {value!r}"
                )
            validate = getattr(value, "validate", None)
            if callable(validate):
                validate()
        if self.controller_feedback not in ("measured", "command"):
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
            _number(o, "duration_s", self.duration_s, low=0.0, low_open=True)

    @property
    def total_duration_s(self) -> float:
        """The simulated time of a full run, s."""
        if self.duration_s is not None:
            return float(self.duration_s)
        return self.trajectory.end_time_s + 1.0


# --------------------------------------------------------------------------
# YAML through Drake's typed loader, via a mutable twin of the schema.

_TWINS: dict[type, type] = {}


def _twin_annotation(tp):
    """The annotation the Drake loader understands for a real annotation."""
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        return _twin_class(tp)
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin in (list, tuple):
        # Homogeneous tuples (tuple[float, ...] or tuple[float, float]) load as lists.
        return list[_twin_annotation(args[0])] if args else list
    if origin is dict:
        return dict[args[0], _twin_annotation(args[1])]
    if origin in (typing.Union, types.UnionType):
        inner = [a for a in args if a is not type(None)]
        if len(inner) == 1 and len(args) == 2:
            return typing.Optional[_twin_annotation(inner[0])]  # noqa: UP045 (Drake reads Optional)
        raise TypeError(f"unsupported union annotation {tp!r} in a scenario schema")
    return tp


def _field_default(f: dataclasses.Field):
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    raise TypeError(f"scenario schema field {f.name!r} has no default")


def _twin_class(cls: type) -> type:
    """A mutable dataclass with cls's fields, resolved types, no validation."""
    if cls in _TWINS:
        return _TWINS[cls]
    hints = typing.get_type_hints(cls)
    specs = []
    for f in dataclasses.fields(cls):
        if not f.init:
            continue
        default = _field_default(f)
        specs.append(
            (
                f.name,
                _twin_annotation(hints[f.name]),
                field(default_factory=lambda d=default: _to_twin(d)),
            )
        )
    twin = dataclasses.make_dataclass(f"_{cls.__name__}Yaml", specs)
    _TWINS[cls] = twin
    return twin


def _to_twin(value):
    """A real value (dataclass tree) as its mutable twin."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        twin = _twin_class(type(value))
        return twin(
            **{
                f.name: _to_twin(getattr(value, f.name))
                for f in dataclasses.fields(twin)
            }
        )
    if isinstance(value, (list, tuple)):
        return [_to_twin(v) for v in value]
    if isinstance(value, dict):
        return {k: _to_twin(v) for k, v in value.items()}
    return value


def _from_twin(value, tp):
    """Rebuilds the real annotation tp from a loaded twin value (runs validation)."""
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        hints = typing.get_type_hints(tp)
        kwargs = {
            f.name: _from_twin(getattr(value, f.name), hints[f.name])
            for f in dataclasses.fields(tp)
            if f.init
        }
        return tp(**kwargs)
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin is list:
        return [_from_twin(v, args[0] if args else typing.Any) for v in value]
    if origin is tuple:
        return tuple(_from_twin(v, args[0] if args else typing.Any) for v in value)
    if origin is dict:
        return {k: _from_twin(v, args[1]) for k, v in value.items()}
    if origin in (typing.Union, types.UnionType):
        if value is None:
            return None
        inner = [a for a in args if a is not type(None)][0]
        return _from_twin(value, inner)
    return value


def load_scenario(path: str | os.PathLike) -> Scenario:
    """Loads a scenario YAML with ``yaml_load_typed`` and validates it.

    Fields missing from the file keep their defaults; unknown fields, wrong
    types and invalid values raise.

    Raises:
        VicDrakeError: naming the file and the offending field and value.
    """
    path = Path(path)
    if not path.is_file():
        raise VicDrakeError(f"scenario file {str(path)!r} does not exist")
    return _load(_SourceLoader(filename=str(path)), f"scenario file {str(path)!r}")


def loads_scenario(text: str) -> Scenario:
    """Like :func:`load_scenario`, from YAML text."""
    return _load(_SourceLoader(data=text), "scenario YAML")


class _SourceLoader:
    """yaml_load_typed on one source (file or text), remembered for error paths."""

    def __init__(self, **source):
        self._source = source

    def __call__(self, schema):
        from pydrake.common.yaml import yaml_load_typed

        return yaml_load_typed(schema=schema, **self._source)


def _load(loader, where: str) -> Scenario:
    try:
        twin = loader(_twin_class(Scenario))
    except VicDrakeError as exc:
        raise VicDrakeError(f"{where}: {exc}") from None
    except Exception as exc:  # Drake's loader raises RuntimeError/yaml errors.
        located = _locate_error(loader, exc)
        raise VicDrakeError(
            f"{where}: {located} (the fields and types are those of vic_drake.scenario.Scenario)"
        ) from None
    try:
        return _from_twin(twin, Scenario)
    except VicDrakeError as exc:
        raise VicDrakeError(f"{where}: {exc}") from None
    except (TypeError, ValueError) as exc:
        raise VicDrakeError(f"{where}: {exc}") from None


def _locate_error(loader, exc: Exception) -> str:
    """Names the field path of a type error the Drake loader reported without one."""
    from pydrake.common.yaml import yaml_load

    source = getattr(loader, "_source", None)
    if source is None:
        return str(exc)
    try:
        raw = yaml_load(**source)
    except Exception:
        return str(exc)
    path = _first_bad_field(raw, _twin_class(Scenario), "")
    return f"field {path}" if path else str(exc)


_SCALARS = {float: (int, float), int: (int,), str: (str,), bool: (bool,)}


def _first_bad_field(value, tp, path: str) -> str | None:
    """Path and problem of the first value that does not fit annotation tp."""
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            return f"{path or '<root>'} must be a mapping; got {value!r}"
        hints = {f.name: f.type for f in dataclasses.fields(tp)}
        for key, item in value.items():
            if key not in hints:
                return (
                    f"{path}.{key}".lstrip(".")
                    + f" is unknown; allowed: {sorted(hints)}"
                )
            bad = _first_bad_field(item, hints[key], f"{path}.{key}".lstrip("."))
            if bad:
                return bad
        return None
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin in (typing.Union, types.UnionType):
        if value is None:
            return None
        return _first_bad_field(
            value, [a for a in args if a is not type(None)][0], path
        )
    if origin is list:
        if not isinstance(value, list):
            return f"{path} must be a list; got {value!r}"
        for i, item in enumerate(value):
            bad = _first_bad_field(
                item, args[0] if args else typing.Any, f"{path}[{i}]"
            )
            if bad:
                return bad
        return None
    if tp in _SCALARS:
        ok = isinstance(value, _SCALARS[tp]) and not (
            tp is not bool and isinstance(value, bool)
        )
        if not ok:
            return f"{path} must be a {tp.__name__}; got {value!r}"
    return None


def dumps_scenario(scenario: Scenario, *, only_changes: bool = False) -> str:
    """The scenario as YAML text (``yaml_dump_typed``), loadable by load_scenario.

    Args:
        scenario: what to write.
        only_changes: write only the fields that differ from ``Scenario()``
            (Drake's ``defaults=``), as the files in ``diagrams/`` do: short,
            and they follow improvements of the defaults. False (default)
            writes every field: the exact record of a run.
    """
    from pydrake.common.yaml import yaml_dump_typed

    if not isinstance(scenario, Scenario):
        raise VicDrakeError(
            f"dumps_scenario needs a Scenario; got {type(scenario).__name__}"
        )
    defaults = _to_twin(Scenario()) if only_changes else None
    return yaml_dump_typed(
        _to_twin(scenario), schema=_twin_class(Scenario), defaults=defaults
    )


def save_scenario(
    scenario: Scenario, path: str | os.PathLike, *, only_changes: bool = False
) -> Path:
    """Writes the scenario as YAML (see :func:`dumps_scenario`); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(dumps_scenario(scenario, only_changes=only_changes))
    return path


__all__ = [
    "DisturbanceConfig",
    "LoggingConfig",
    "PhantomConfig",
    "PhantomLift",
    "Scenario",
    "TrajectoryConfig",
    "dumps_scenario",
    "load_scenario",
    "loads_scenario",
    "save_scenario",
]
