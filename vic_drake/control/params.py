"""Parameters of the online controller: energy tank, stiffness QP, references.

Defaults are the real controller's settings (``../shared/data/README.md``,
"The real controller's settings"). Every field carries its unit in its name
or comment. All vectors are per Cartesian axis (x, y, z) in the robot base
frame W.

The dataclasses are mutable on purpose: Drake's ``yaml_load_typed`` fills a
default-constructed instance field by field, which a frozen dataclass forbids.
Validation therefore runs twice: in ``__post_init__`` (direct construction)
and in :meth:`validate`, which every builder (``MakeVariableImpedanceController``,
the LeafSystems, the replay) calls again on what it is given, so values
loaded from YAML are checked too. Every message names the field and the value.

(No ``from __future__ import annotations`` here: Drake's YAML loader reads
the field types at run time.)
"""

from dataclasses import dataclass, field

from vic_drake.errors import VicDrakeError, check_number
from vic_drake.paper import CONTACT_THRESHOLD_N, CONTROLLERS

__all__ = [
    "CONTROLLERS",  # Re-exported from vic_drake.paper (its old home).
    "MAX_FORCE_N",
    "MAX_PENETRATION_M",
    "SURFACE_VELOCITY_MODES",
    "ControllerParams",
    "ReferenceParams",
    "StiffnessQpParams",
    "TankParams",
    "real_controller_params",
]

#: The largest penetration a reference may ask for (eps_max_m, eps_d_m), m:
#: 5 cm, past any probe's use on soft tissue (the paper's are 8 mm).
MAX_PENETRATION_M = 0.05

#: The largest pressing force a reference may ask for (force_ref_N,
#: |force_min_z_N|), N: ultrasonography presses up to ~20 N; past 50 N is a
#: typo (the rig's safety limit is 15 N).
MAX_FORCE_N = 50.0

#: Modes of the surface-velocity estimate used in the penetration rate.
SURFACE_VELOCITY_MODES = ("moving_average", "gradient")


def _vec3(owner: str, name: str, value) -> list[float]:
    try:
        items = list(value)
    except TypeError:
        raise VicDrakeError(
            f"{owner}.{name} must be 3 numbers (x, y, z); got {value!r}"
        ) from None
    if len(items) != 3:
        raise VicDrakeError(
            f"{owner}.{name} must be 3 numbers (x, y, z); got {value!r}"
        )
    return [check_number(owner, f"{name}[{i}]", v) for i, v in enumerate(items)]


def _positive(owner: str, name: str, value) -> float:
    v = check_number(owner, name, value)
    if not v > 0.0:
        raise VicDrakeError(f"{owner}.{name} must be > 0; got {value!r}")
    return v


@dataclass
class TankParams:
    """The energy tank of the paper (state x_t, energy T = x_t^2 / 2).

    Attributes:
        initial_energy_J: T at start (real controller: x_t = 1, T = 0.5 J).
        min_energy_J: T_min; below it the variable stiffness is disabled
            (K = K_min) and the QP's first tank row keeps T >= T_min. > 0.
        max_energy_J: T_max; sigma = 0 (no storage of damping energy) when
            T >= T_max, else 1. > min_energy_J.
        power_limit_W: eta, the most negative allowed tank power dT/dt
            (the "power valve"); < 0. The real controller: -0.1 W.
        floor_at_min: when the tank is found below T_min (only possible if
            it starts there), reset it to T_min + sigma e_dot' D e_dot dt as
            the real controller did; if False it keeps integrating from the
            lower value (paper: w = 0, only damping energy flows in).
    """

    initial_energy_J: float = 0.5
    min_energy_J: float = 0.4
    max_energy_J: float = 1.0
    power_limit_W: float = -0.1
    floor_at_min: bool = True

    def __post_init__(self):
        self.validate()

    def validate(self) -> "TankParams":
        o = "TankParams"
        t_min = _positive(o, "min_energy_J", self.min_energy_J)
        t_max = check_number(o, "max_energy_J", self.max_energy_J)
        if not t_max > t_min:
            raise VicDrakeError(
                f"{o}.max_energy_J must be > min_energy_J ({t_min!r}); got {self.max_energy_J!r}"
            )
        t0 = check_number(o, "initial_energy_J", self.initial_energy_J)
        if t0 < 0.0:
            raise VicDrakeError(
                f"{o}.initial_energy_J must be >= 0; got {self.initial_energy_J!r}"
            )
        eta = check_number(o, "power_limit_W", self.power_limit_W)
        if not eta < 0.0:
            raise VicDrakeError(
                f"{o}.power_limit_W (eta, the most negative tank power) must be < 0; "
                f"got {self.power_limit_W!r}"
            )
        if not isinstance(self.floor_at_min, bool):
            raise VicDrakeError(
                f"{o}.floor_at_min must be true or false; got {self.floor_at_min!r}"
            )
        return self


@dataclass
class StiffnessQpParams:
    """The per-tick stiffness QP (eq. 8, diagonal form as the real controller).

    Cost sum_i Q_i (e_i k_i + D_i e_dot_i - F_ref_i)^2 + R_i (k_i - K_min_i)^2.

    Attributes:
        q_weight: Q per axis (force tracking weight, 1/N^2 scale). > 0.
        r_weight: R per axis (stiffness regularisation). > 0 (the QP must be
            strictly convex). The real logs: 0.1 (test_tracking5, VS-CF) and
            1e-5 (test_nardi_matForce_lowR, VS-VF).
        stiffness_min_N_per_m: K_min per axis, >= 0.
        stiffness_max_N_per_m: K_max per axis, >= K_min.
        force_min_N: F_min per axis (sensor convention, negative = pressing);
            on z it is replaced by the reference law of the VS controllers.
        force_max_N: F_max per axis, > F_min.
        damping_ratio: zeta in D = 2 zeta sqrt(K) (real controller: 0.707).
        solver: "osqp" (default) or "clarabel", through Drake's
            MathematicalProgram, or "exact", the closed-form solver of this
            package (the same answer, cheaper per tick: the fast path; see
            docs/decisions.md, "Stiffness QP solvers and scaling").
        osqp_eps: OSQP eps_abs = eps_rel. OSQP runs without its polishing
            step (which prints notes on stdout), so the tolerance is tight
            (see docs/decisions.md, "OSQP settings").
    """

    q_weight: list[float] = field(default_factory=lambda: [3200.0, 3200.0, 3200.0])
    r_weight: list[float] = field(default_factory=lambda: [0.1, 0.1, 0.1])
    stiffness_min_N_per_m: list[float] = field(
        default_factory=lambda: [300.0, 300.0, 100.0]
    )
    stiffness_max_N_per_m: list[float] = field(
        default_factory=lambda: [1000.0, 1000.0, 1000.0]
    )
    force_min_N: list[float] = field(default_factory=lambda: [-15.0, -15.0, -15.0])
    force_max_N: list[float] = field(default_factory=lambda: [15.0, 15.0, 15.0])
    damping_ratio: float = 0.707
    solver: str = "osqp"
    osqp_eps: float = 1e-12

    def __post_init__(self):
        self.validate()

    def validate(self) -> "StiffnessQpParams":
        o = "StiffnessQpParams"
        for name in ("q_weight", "r_weight"):
            for i, v in enumerate(_vec3(o, name, getattr(self, name))):
                if not v > 0.0:
                    raise VicDrakeError(f"{o}.{name}[{i}] must be > 0; got {v!r}")
        k_min = _vec3(o, "stiffness_min_N_per_m", self.stiffness_min_N_per_m)
        k_max = _vec3(o, "stiffness_max_N_per_m", self.stiffness_max_N_per_m)
        f_min = _vec3(o, "force_min_N", self.force_min_N)
        f_max = _vec3(o, "force_max_N", self.force_max_N)
        for i in range(3):
            if k_min[i] < 0.0:
                raise VicDrakeError(
                    f"{o}.stiffness_min_N_per_m[{i}] must be >= 0; got {k_min[i]!r}"
                )
            if k_min[i] > k_max[i]:
                raise VicDrakeError(
                    f"{o}.stiffness_min_N_per_m[{i}] = {k_min[i]!r} exceeds "
                    f"stiffness_max_N_per_m[{i}] = {k_max[i]!r}; need K_min <= K_max"
                )
            if not f_min[i] < f_max[i]:
                raise VicDrakeError(
                    f"{o}.force_min_N[{i}] = {f_min[i]!r} must be < force_max_N[{i}] = {f_max[i]!r}"
                )
        zeta = check_number(o, "damping_ratio", self.damping_ratio)
        if zeta < 0.0:
            raise VicDrakeError(
                f"{o}.damping_ratio must be >= 0; got {self.damping_ratio!r}"
            )
        if self.solver not in ("exact", "osqp", "clarabel"):
            raise VicDrakeError(
                f"{o}.solver must be 'exact', 'osqp' or 'clarabel'; got {self.solver!r}"
            )
        _positive(o, "osqp_eps", self.osqp_eps)
        return self


@dataclass
class ReferenceParams:
    """Force references, contact detection and the tissue model's use.

    How each controller maps to (stiffness, target_force) for the FDCC
    (forward dynamics compliance control) stage, sensor sign convention
    (negative z = pressing into the body):

    - "cs": constant stiffness ``constant_stiffness_N_per_m`` on all axes, no
      QP, no tank; target_force = 0 (the real CS baseline used 400 N/m).
    - "cf": force control on z: stiffness (K_x, K_y, 0) with K_x, K_y from
      ``constant_stiffness_N_per_m``; target_force = (0, 0, -force_ref_N)
      at all times (in free space the force error drives the probe down
      until it touches). No QP, no tank.
    - "vs-cf": QP stiffness; F_ref,z = -force_ref_N in contact,
      F_min,z = -(kappa + lam eps_dot) eps_max^beta (eq. 9); target_force = 0
      (the real VS controllers sent only the stiffness to the FZI cartesian
      compliance controller; the force is regulated through K).
    - "vs-vf": QP stiffness; F_ref,z = -(kappa + lam eps_dot) eps_d^beta in
      contact, F_min,z = force_min_z_N; target_force = 0.

    Out of contact (sensor z force >= -contact_threshold_N) the VS
    controllers use F_ref = 0 and F_min,z = -F_max,z, as the real one did.

    Attributes:
        controller: one of "cs", "cf", "vs-cf", "vs-vf".
        force_ref_N: pressing force magnitude for CF and VS-CF, N (> 0);
            the reference is -force_ref_N in the sensor convention.
        force_min_z_N: constant F_min,z of VS-VF (sensor convention, < 0).
        eps_max_m: maximum penetration of VS-CF, m (> 0).
        eps_d_m: desired penetration of VS-VF, m (> 0).
        contact_threshold_N: contact when sensor z force < -threshold, N.
        constant_stiffness_N_per_m: stiffness of CS (all axes) and of CF
            (x and y only), N/m.
        surface_velocity_mode: "moving_average" (real controller: mean of
            the last ``surface_velocity_window`` finite differences of the
            map height under the probe) or "gradient" (grad z . (vx, vy),
            instantaneous).
        surface_velocity_window: samples in the moving average (>= 1).
        penetration_dither_m: VS-VF only: amplitude of a sinusoidal dither
            of the desired penetration, eps_d(t) = eps_d_m +
            penetration_dither_m sin(2 pi penetration_dither_hz t), m
            (0 = off, the default; at most eps_d_m / 2). It excites the
            tissue so that an online estimator can tell kappa from the
            surface (:func:`vic_drake.control.references.desired_penetration`).
        penetration_dither_hz: its frequency, Hz (> 0; at most a tenth of
            the control rate, :class:`ControllerParams`).
    """

    controller: str = "vs-cf"
    force_ref_N: float = 7.0
    force_min_z_N: float = -9.0
    eps_max_m: float = 0.008
    eps_d_m: float = 0.008
    contact_threshold_N: float = CONTACT_THRESHOLD_N
    constant_stiffness_N_per_m: list[float] = field(
        default_factory=lambda: [400.0, 400.0, 400.0]
    )
    surface_velocity_mode: str = "moving_average"
    surface_velocity_window: int = 10
    penetration_dither_m: float = 0.0
    penetration_dither_hz: float = 3.0

    def __post_init__(self):
        self.validate()

    def validate(self) -> "ReferenceParams":
        o = "ReferenceParams"
        if self.controller not in CONTROLLERS:
            raise VicDrakeError(
                f"{o}.controller must be one of {list(CONTROLLERS)}; got {self.controller!r}"
            )
        if _positive(o, "force_ref_N", self.force_ref_N) > MAX_FORCE_N:
            raise VicDrakeError(
                f"{o}.force_ref_N must be at most {MAX_FORCE_N:g} N; got "
                f"{self.force_ref_N!r}"
            )
        if check_number(o, "force_min_z_N", self.force_min_z_N) < -MAX_FORCE_N:
            raise VicDrakeError(
                f"{o}.force_min_z_N must be >= {-MAX_FORCE_N:g} N; got "
                f"{self.force_min_z_N!r}"
            )
        if not self.force_min_z_N < 0.0:
            raise VicDrakeError(
                f"{o}.force_min_z_N must be < 0 (sensor convention, pressing); "
                f"got {self.force_min_z_N!r}"
            )
        for name in ("eps_max_m", "eps_d_m"):
            value = _positive(o, name, getattr(self, name))
            if value > MAX_PENETRATION_M:  # E.g. 8 (mm) typed for 0.008 (m).
                raise VicDrakeError(
                    f"{o}.{name} is in metres and must be at most "
                    f"{MAX_PENETRATION_M:g} m; got {value!r} (0.008 is 8 mm)"
                )
        if check_number(o, "contact_threshold_N", self.contact_threshold_N) < 0.0:
            raise VicDrakeError(
                f"{o}.contact_threshold_N must be >= 0; got {self.contact_threshold_N!r}"
            )
        for i, v in enumerate(
            _vec3(o, "constant_stiffness_N_per_m", self.constant_stiffness_N_per_m)
        ):
            if v < 0.0:
                raise VicDrakeError(
                    f"{o}.constant_stiffness_N_per_m[{i}] must be >= 0; got {v!r}"
                )
        if self.surface_velocity_mode not in SURFACE_VELOCITY_MODES:
            raise VicDrakeError(
                f"{o}.surface_velocity_mode must be one of {list(SURFACE_VELOCITY_MODES)}; "
                f"got {self.surface_velocity_mode!r}"
            )
        w = self.surface_velocity_window
        if isinstance(w, bool) or not isinstance(w, int) or w < 1:
            raise VicDrakeError(
                f"{o}.surface_velocity_window must be an integer >= 1; got {w!r}"
            )
        self._validate_dither(o)
        return self

    def _validate_dither(self, o: str) -> None:
        for name in ("penetration_dither_m", "penetration_dither_hz"):
            if isinstance(getattr(self, name), bool):
                raise VicDrakeError(
                    f"{o}.{name} must be a number; got {getattr(self, name)!r}"
                )
        a = check_number(o, "penetration_dither_m", self.penetration_dither_m)
        if not 0.0 <= a <= 0.5 * self.eps_d_m:
            raise VicDrakeError(
                f"{o}.penetration_dither_m must be in [0, eps_d_m / 2] = "
                f"[0, {0.5 * self.eps_d_m!r}] m (0 = off); got {self.penetration_dither_m!r}"
            )
        _positive(o, "penetration_dither_hz", self.penetration_dither_hz)
        if a > 0.0 and self.controller != "vs-vf":
            raise VicDrakeError(
                f"{o}.penetration_dither_m needs controller 'vs-vf' (the only "
                f"reference with a desired penetration); got controller "
                f"{self.controller!r} with penetration_dither_m {a!r}"
            )


@dataclass
class ControllerParams:
    """The whole online controller (reference + QP + tank) at one rate.

    Attributes:
        period_s: control period, s (real controller: 500 Hz). > 0.
        tank: energy tank.
        qp: stiffness QP.
        reference: force references and controller kind.
    """

    period_s: float = 0.002
    tank: TankParams = field(default_factory=TankParams)
    qp: StiffnessQpParams = field(default_factory=StiffnessQpParams)
    reference: ReferenceParams = field(default_factory=ReferenceParams)

    def __post_init__(self):
        self.validate()

    def validate(self) -> "ControllerParams":
        period = _positive("ControllerParams", "period_s", self.period_s)
        for name, kind in (
            ("tank", TankParams),
            ("qp", StiffnessQpParams),
            ("reference", ReferenceParams),
        ):
            value = getattr(self, name)
            if not isinstance(value, kind):
                raise VicDrakeError(
                    f"ControllerParams.{name} must be a {kind.__name__}; got {value!r}"
                )
            value.validate()
        hz = self.reference.penetration_dither_hz
        if hz > 0.1 / period:
            raise VicDrakeError(
                "ControllerParams.reference.penetration_dither_hz must be at most "
                f"a tenth of the control rate (0.1 / period_s = {0.1 / period!r} Hz); "
                f"got {hz!r}"
            )
        return self


def real_controller_params(controller: str) -> ControllerParams:
    """The settings of the paper's real runs for one controller.

    - "cs": 400 N/m on every axis (test_compliance_control400).
    - "cf": 7 N pressing, x/y at 400 N/m (test_force_control).
    - "vs-cf": 7 N reference, eps_max = 8 mm, R = 0.1 (test_tracking5).
    - "vs-vf": eps_d = 8 mm, F_min,z = -9 N, R = 1e-5
      (test_nardi_matForce_lowR).
    """
    if controller not in CONTROLLERS:
        raise VicDrakeError(
            f"controller must be one of {list(CONTROLLERS)}; got {controller!r}"
        )
    r = 1e-5 if controller == "vs-vf" else 0.1
    return ControllerParams(
        qp=StiffnessQpParams(r_weight=[r, r, r]),
        reference=ReferenceParams(controller=controller),
    )
