"""Layouts of the controller's packed vector ports, each defined once.

Most controller signals are ports of their own. A few vectors stay packed
(see docs/decisions.md, "Controller signals") and are described here, the
one place both their writer and their readers take the layout from:

- ``measurement`` (ForceReferenceSystem's input): what a tick reads,
  one vector (one port evaluation per tick).
- ``references`` (ForceReferenceSystem): the tick's references, computed
  with direct feedthrough from the current measurement; with the probe
  position and velocity the tick read, the head of its "tick" vector, they
  are the ``reference_tick`` part of StiffnessQpSystem's ``inputs`` vector
  (one port evaluation per tick: C++ Demultiplexers and a Multiplexer in
  the controller Diagram).
- ``contact`` (ForceReferenceSystem, state of the last tick): the contact
  part of ``references``.
- ``qp_tick`` (StiffnessQpSystem -> EnergyTankSystem): what the QP's last
  tick used, which the tank integrates within the same tick. One port keeps
  the tank's step at one port evaluation per tick.
- ``inputs`` (FdccController): the FDCC tick's five inputs, one vector
  (one port evaluation per tick: a C++ Multiplexer in the scan Diagram).
- ``status`` (StiffnessQpSystem) and ``tank`` (EnergyTankSystem): records
  logged as one vector each; :data:`STATUS_FIELDS` and :data:`TANK_FIELDS`
  name their elements in order.
"""

from __future__ import annotations

#: Elements of the "contact" port, in order: 1 in contact else 0; the
#: map-based penetration eps = surface_z - z, m; 1 on a non-finite input
#: else 0; the surface-velocity estimate, m/s.
CONTACT_FIELDS = ("in_contact", "penetration_m", "fault", "surface_velocity_m_per_s")
CONTACT_SIZE = len(CONTACT_FIELDS)

#: Elements of ForceReferenceSystem's "tick_record" port, in order: what
#: the tick read (probe position p_WP, m; velocity v_WP, m/s; F/T force in
#: W, N, sensor convention) and what its map lookup returned (Hunt-Crossley
#: kappa, N/m^beta; lambda, N s/m^(beta+1)): the real controller's log
#: columns 1-3, 27-29, 8-10, 20-21.
TICK_RECORD_FIELDS = (
    "x_m",
    "y_m",
    "z_m",
    "vx_m_per_s",
    "vy_m_per_s",
    "vz_m_per_s",
    "force_x_N",
    "force_y_N",
    "force_z_N",
    "kappa",
    "lambda",
)
TICK_RECORD_SIZE = len(TICK_RECORD_FIELDS)

#: ForceReferenceSystem's "measurement" input: what a tick reads, the first
#: nine :data:`TICK_RECORD_FIELDS` (p_WP, m; v_WP, m/s; F/T force in W, N).
MEASURED_POSITION = slice(0, 3)
MEASURED_VELOCITY = slice(3, 6)
MEASURED_FORCE = slice(6, 9)
MEASUREMENT_SIZE = MEASURED_FORCE.stop

#: The "references" port: F_ref (3, N), F_min (3, N), the FDCC target force
#: (3, N), then the :data:`CONTACT_FIELDS`.
REFERENCES_SIZE = 9 + CONTACT_SIZE
REF_FORCE_REFERENCE = slice(0, 3)
REF_FORCE_MIN = slice(3, 6)
REF_TARGET_FORCE = slice(6, 9)
REF_CONTACT = slice(9, REFERENCES_SIZE)
REF_IN_CONTACT = 9 + CONTACT_FIELDS.index("in_contact")
REF_PENETRATION = 9 + CONTACT_FIELDS.index("penetration_m")
REF_FAULT = 9 + CONTACT_FIELDS.index("fault")
REF_SURFACE_VELOCITY = 9 + CONTACT_FIELDS.index("surface_velocity_m_per_s")

#: The "reference_tick" part of StiffnessQpSystem's inputs: the head of
#: ForceReferenceSystem's "tick" output, i.e. the "references" then the
#: probe position p_WP (3, m) and velocity v_WP (3, m/s) the tick read (the
#: first six :data:`TICK_RECORD_FIELDS`): the QP uses the measurement its
#: references were computed from.
REFERENCE_TICK_SIZE = REFERENCES_SIZE + 6
REF_PROBE_POSITION = slice(REFERENCES_SIZE, REFERENCES_SIZE + 3)
REF_PROBE_VELOCITY = slice(REFERENCES_SIZE + 3, REFERENCE_TICK_SIZE)

#: StiffnessQpSystem's one "inputs" vector (a C++ Multiplexer builds it in
#: the controller Diagram): the target position x_d (3, m), the
#: "reference_tick" above, then the tank's energy T before the tick (1, J).
QP_IN_TARGET = slice(0, 3)
QP_IN_REFERENCE_TICK = slice(3, 3 + REFERENCE_TICK_SIZE)
QP_IN_TANK_ENERGY = QP_IN_REFERENCE_TICK.stop
QP_INPUTS_SIZE = QP_IN_TANK_ENERGY + 1

#: FdccController's one "inputs" vector (a C++ Multiplexer builds it, see
#: :func:`vic_drake.systems.fdcc.AddFdccInputs`): the measured joint angles
#: q (6, rad), the target tip position x_d (3, m, W), the stiffness K (3,
#: N/m), the F/T force in W (3, N, sensor convention) and the target force
#: (3, N, same convention). :data:`FDCC_INPUT_PARTS` names them in order.
FDCC_IN_JOINT_POSITIONS = slice(0, 6)
FDCC_IN_TARGET_POSITION = slice(6, 9)
FDCC_IN_STIFFNESS = slice(9, 12)
FDCC_IN_FORCE = slice(12, 15)
FDCC_IN_TARGET_FORCE = slice(15, 18)
FDCC_INPUTS_SIZE = FDCC_IN_TARGET_FORCE.stop
FDCC_INPUT_PARTS = (
    ("joint_positions", FDCC_IN_JOINT_POSITIONS),
    ("target_position", FDCC_IN_TARGET_POSITION),
    ("stiffness", FDCC_IN_STIFFNESS),
    ("ft_sensor.force_W", FDCC_IN_FORCE),
    ("target_force", FDCC_IN_TARGET_FORCE),
)


def widths(parts) -> list[int]:
    """The lengths of the slices ``parts``, in order (a Multiplexer's input
    sizes for the vector they tile)."""
    return [part.stop - part.start for part in parts]


#: The "qp_tick" port: the QP's last tick as the tank integrates it.
#: e = x_d - x (3, m), e_dot = -x_dot (3, m/s), K (3, N/m), the damping D
#: the tick used (3, N s/m: 2 zeta sqrt of the previous tick's K), and
#: 1 when the tick ran the variable stiffness (VS controllers) else 0
#: (before the first tick, CS and CF: the tank then holds its energy).
QP_TICK_POSITION_ERROR = slice(0, 3)
QP_TICK_VELOCITY_ERROR = slice(3, 6)
QP_TICK_STIFFNESS = slice(6, 9)
QP_TICK_DAMPING_USED = slice(9, 12)
QP_TICK_ACTIVE = 12
QP_TICK_SIZE = 13

#: Elements of the QP system's "status" port, in order.
STATUS_FIELDS = (
    "qp_ok",
    "fallback_count",
    "fault",
    "in_contact",
    "solve_time_s",
    "penetration_m",
)
STATUS_QP_OK = STATUS_FIELDS.index("qp_ok")
STATUS_FALLBACK_COUNT = STATUS_FIELDS.index("fallback_count")

#: Elements of the tank system's "tank" port, in order: T after the tick, J;
#: dT/dt, W; sigma (0/1); enabled (0/1).
TANK_FIELDS = ("T_J", "power_W", "sigma", "enabled")
TANK_ENERGY = TANK_FIELDS.index("T_J")
