"""The variable impedance controller: references + stiffness QP + energy tank.

``MakeVariableImpedanceController(params, phantom=...)`` returns a Diagram
named "variable_impedance_controller" composing

- "force_reference" (:class:`ForceReferenceSystem`): contact, penetration
  rate, F_ref, F_min, the FDCC target force,
- "stiffness_qp" (:class:`StiffnessQpSystem`): K (QP or constant), D,
  status, and the record of its tick ("qp_tick") the tank integrates,
- "energy_tank" (:class:`EnergyTankSystem`): T, power, sigma, enabled,

all at ``params.period_s`` (500 Hz by default). The QP reads its references
and the probe position and velocity they were computed from (the head of
"force_reference"'s "tick" vector) and T (an element of the tank's "tank"
record) through two C++ Demultiplexers, "reference_fields" and
"tank_fields", so that neither read calls Python. The reference system and
the QP each read their inputs as one vector built by a C++ Multiplexer
("measurement": the three measured inputs, which the online estimator
reads too; "qp_inputs": x_d, the reference tick's head, T). All four controllers (CS, CF, VS-CF, VS-VF) expose the
same ports; see
:class:`vic_drake.control.params.ReferenceParams` for how each maps to
(stiffness, target_force) of the compliance (FDCC) stage.
"""

from __future__ import annotations

from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import Demultiplexer, Multiplexer

from vic_drake.control.params import ControllerParams
from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online import OnlineEstimatorParams
from vic_drake.systems.online_estimator import OnlineEstimatorSystem
from vic_drake.systems.references import ForceReferenceSystem
from vic_drake.systems.signals import (
    MEASURED_FORCE,
    MEASURED_POSITION,
    MEASURED_VELOCITY,
    QP_IN_REFERENCE_TICK,
    QP_IN_TARGET,
    REFERENCE_TICK_SIZE,
    STATUS_FIELDS,
    TANK_ENERGY,
    TANK_FIELDS,
    widths,
)
from vic_drake.systems.stiffness_qp import StiffnessQpSystem
from vic_drake.systems.tank import EnergyTankSystem
from vic_drake.tissue.phantom import Phantom

__all__ = [
    "MakeVariableImpedanceController",
    "STATUS_FIELDS",
    "TANK_FIELDS",
]


def MakeVariableImpedanceController(
    params: ControllerParams,
    *,
    phantom: Phantom | None,
    stiffness_source: str = "map",
    estimator: OnlineEstimatorParams | None = None,
    online_surface: str = "estimated",
) -> Diagram:
    """Builds the online controller.

    Args:
        params: controller parameters (validated here again, so values loaded
            from YAML are checked).
        phantom: the tissue map the references read (surface, kappa, lam);
            may be None with ``stiffness_source="online"``.
        stiffness_source: "map" or "online": kappa, lam and the surface come
            from an OnlineEstimatorSystem ("tissue_estimator", fed by the
            probe and the sensor, seeded with the estimator's prior) and the
            diagram exports its "tissue_estimate" (7) output too.
        estimator: the estimator's settings (needed with "online").
        online_surface: with "online": "estimated" (latched at first
            contact; the phantom is not read) or "map" (the estimator reads
            the phantom's surface under the probe; kappa, lam still online).

    Returns:
        Diagram "variable_impedance_controller" with
        inputs: "probe.position" (3, p_WP, m), "probe.velocity" (3, v_WP,
        m/s), "target_position" (3, x_d, m), "ft_sensor.force_W" (3, N, in
        W, sensor convention: negative z = pressing);
        outputs: "stiffness" (3, N/m), "damping" (3, N s/m), "target_force"
        (3, N), "force_reference" (3, N), "force_min" (3, N), "tank" (4:
        :data:`TANK_FIELDS`), "status" (6: :data:`STATUS_FIELDS`),
        "contact" (4: :data:`vic_drake.systems.signals.CONTACT_FIELDS`),
        "tick_record" (11: :data:`vic_drake.systems.signals.TICK_RECORD_FIELDS`,
        what the tick read and its map sample). All but
        "target_force" (direct feedthrough, read by the compliance stage in
        the same tick) describe the last tick (from state):
        force_reference and force_min are what that tick's QP used.
    """
    if not isinstance(params, ControllerParams):
        raise VicDrakeError(
            f"MakeVariableImpedanceController needs ControllerParams; got {params!r}"
        )
    online = stiffness_source == "online"
    if online and not isinstance(estimator, OnlineEstimatorParams):
        raise VicDrakeError(
            f"stiffness_source 'online' needs estimator=OnlineEstimatorParams; got {estimator!r}"
        )
    if online_surface not in ("estimated", "map"):
        raise VicDrakeError(
            f"online_surface must be 'estimated' or 'map'; got {online_surface!r}"
        )
    if (not online or online_surface == "map") and not isinstance(phantom, Phantom):
        raise VicDrakeError(f"phantom must be a vic_drake Phantom; got {phantom!r}")
    params.validate()
    if online and estimator.validate().surface_from_slope:
        if params.reference.penetration_dither_m == 0.0:
            raise VicDrakeError(
                "the estimator's surface_from_slope needs the reference's dither "
                "(reference.penetration_dither_m > 0); got 0.0"
            )
    reads_bounds = online and estimator.reads_controller_bounds
    builder = DiagramBuilder()
    ref = builder.AddNamedSystem(
        "force_reference",
        ForceReferenceSystem(
            params,
            phantom=phantom,
            stiffness_source=stiffness_source,
            beta=estimator.beta if online else None,
        ),
    )
    if online:
        est = builder.AddNamedSystem(
            "tissue_estimator",
            OnlineEstimatorSystem(
                estimator,
                period_s=params.period_s,
                surface_input=False,
                surface_map=phantom if online_surface == "map" else None,
                stiffness_max_z=params.qp.stiffness_max_N_per_m[2]
                if reads_bounds
                else None,
                force_min_z=params.reference.force_min_z_N if reads_bounds else None,
                dither_hz=params.reference.penetration_dither_hz
                if reads_bounds
                else None,
            ),
        )
        builder.Connect(
            est.get_estimate_output_port(), ref.GetInputPort("tissue.estimate")
        )
        builder.ExportOutput(est.get_estimate_output_port(), "tissue_estimate")
    qp = builder.AddNamedSystem("stiffness_qp", StiffnessQpSystem(params))
    tank = builder.AddNamedSystem("energy_tank", EnergyTankSystem(params))

    # The reference system reads the three measured vectors as one, built by
    # a C++ Multiplexer: one port evaluation per tick instead of three.
    parts = {
        "probe.position": MEASURED_POSITION,
        "probe.velocity": MEASURED_VELOCITY,
        "ft_sensor.force_W": MEASURED_FORCE,
    }
    measurement = builder.AddNamedSystem(
        "measurement", Multiplexer(widths(parts.values()))
    )
    builder.Connect(measurement.get_output_port(0), ref.get_measurement_input_port())
    if online:  # The estimator reads the same vector.
        builder.Connect(
            measurement.get_output_port(0), est.get_measurement_input_port()
        )
    for i, name in enumerate(parts):
        builder.ExportInput(measurement.get_input_port(i), name)
    # The QP reads x_d, its reference tick and T as one vector, built by a C++
    # Multiplexer: one port evaluation per tick instead of three.
    qp_inputs = builder.AddNamedSystem(
        "qp_inputs",
        Multiplexer(widths((QP_IN_TARGET, QP_IN_REFERENCE_TICK)) + [1]),
    )
    builder.Connect(qp_inputs.get_output_port(0), qp.get_inputs_input_port())
    builder.ExportInput(qp_inputs.get_input_port(0), "target_position")

    # The QP reads the references, and the probe's position and velocity they
    # were computed from, from the head of the reference system's "tick"
    # vector through a C++ Demultiplexer: no Python output callback per tick
    # and no Eval of the probe ports of its own.
    ref_fields = builder.AddNamedSystem(
        "reference_fields",
        Demultiplexer(
            [
                REFERENCE_TICK_SIZE,
                ref.get_tick_output_port().size() - REFERENCE_TICK_SIZE,
            ]
        ),
    )
    builder.Connect(ref.get_tick_output_port(), ref_fields.get_input_port())
    builder.Connect(ref_fields.get_output_port(0), qp_inputs.get_input_port(1))
    if reads_bounds:
        # K from state (the last tick's: no algebraic loop); the references
        # through the QP's Demultiplexer (no Python output callback; read in
        # the estimator's update only, so no loop through its estimate).
        builder.Connect(qp.get_stiffness_output_port(), est.get_stiffness_input_port())
        builder.Connect(ref_fields.get_output_port(0), est.get_references_input_port())
    # The QP reads T from the "tank" record through a C++ Demultiplexer: the
    # number of the tank's own "tank_energy" port, with no Python call per tick.
    tank_fields = builder.AddNamedSystem(
        "tank_fields", Demultiplexer(len(TANK_FIELDS), 1)
    )
    builder.Connect(tank.get_tank_output_port(), tank_fields.get_input_port())
    builder.Connect(
        tank_fields.get_output_port(TANK_ENERGY), qp_inputs.get_input_port(2)
    )
    builder.Connect(qp.get_qp_tick_output_port(), tank.get_qp_tick_input_port())

    builder.ExportOutput(qp.get_stiffness_output_port(), "stiffness")
    builder.ExportOutput(qp.get_damping_output_port(), "damping")
    builder.ExportOutput(ref.get_target_force_output_port(), "target_force")
    builder.ExportOutput(ref.get_force_reference_output_port(), "force_reference")
    builder.ExportOutput(ref.get_force_min_output_port(), "force_min")
    builder.ExportOutput(ref.get_contact_output_port(), "contact")
    builder.ExportOutput(ref.get_tick_record_output_port(), "tick_record")
    builder.ExportOutput(tank.get_tank_output_port(), "tank")
    builder.ExportOutput(qp.get_status_output_port(), "status")
    diagram = builder.Build()
    diagram.set_name("variable_impedance_controller")
    return diagram
