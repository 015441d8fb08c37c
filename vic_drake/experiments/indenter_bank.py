"""The indenter bank: n servo-driven 1-DOF indenters palpating tissue in one diagram.

Each indenter is a body on a vertical prismatic joint of a discrete
:class:`MultibodyPlant`, driven by the plant's implicit joint PD controller
towards the desired state of :class:`~vic_drake.systems.indenter.PalpationTarget`
(the position servo of the real Cartesian controller, with gravity
compensated by a feed-forward force); the tissue pushes back through
:class:`~vic_drake.systems.indenter.HuntCrossleyIndentation` and
:class:`~vic_drake.systems.indenter.LaggedForceSensor` reads the force.

Many indenters share one diagram, so a whole campaign costs one simulation:
the per-step Python overhead is paid once for all points, not once per
point. One built diagram is reused for any batch of points by writing a
fresh Context (:meth:`IndenterBank.set_points`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (
    PdControllerGains,
    PrismaticJoint,
    SpatialInertia,
    UnitInertia,
)
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

from vic_drake.errors import VicDrakeError
from vic_drake.paper import GRAVITY_M_PER_S2
from vic_drake.systems.indenter import (
    HuntCrossleyIndentation,
    IndenterParams,
    LaggedForceSensor,
    PalpationParams,
    PalpationTarget,
    SensorParams,
)
from vic_drake.systems.noise_table import NoiseTable
from vic_drake.tissue.relaxation import DEFAULT_RELAXATION, RelaxationParams


@dataclass
class IndenterBank:
    """Handles of a built indenter diagram (see :func:`MakeIndenterDiagram`)."""

    diagram: Diagram
    plant: MultibodyPlant
    tissue: HuntCrossleyIndentation
    sensor: LaggedForceSensor
    target: PalpationTarget
    noise: NoiseTable
    state_logger: object
    force_logger: object
    target_logger: object
    contact_logger: object
    n: int

    def set_points(
        self, root_context, *, surface_z, kappa, lam, start_z, seed=None, ids=None
    ) -> None:
        """Writes the tissue and the start height of every indenter.

        The indenters start at rest at ``start_z``; arrays of shape (n,).
        With ``seed``, indenter i's sensor noise is drawn from ``(seed,
        ids[i])`` (``ids`` default: 0..n-1), so a point's noise does not
        depend on the other points of its batch
        (:class:`~vic_drake.systems.noise_table.NoiseTable`).
        """
        if seed is not None:
            self.noise.set_noise(
                self.noise.GetMyMutableContextFromRoot(root_context),
                seed=int(seed),
                ids=np.arange(self.n) if ids is None else ids,
            )
        self.tissue.set_tissue(
            self.tissue.GetMyMutableContextFromRoot(root_context),
            surface_z=surface_z,
            kappa=kappa,
            lam=lam,
        )
        self.target.set_start_z(
            self.target.GetMyMutableContextFromRoot(root_context), start_z
        )
        plant_context = self.plant.GetMyMutableContextFromRoot(root_context)
        self.plant.SetPositionsAndVelocities(
            plant_context,
            np.concatenate([np.broadcast_to(start_z, (self.n,)), np.zeros(self.n)]),
        )


def MakeIndenterDiagram(
    n: int,
    *,
    beta: float,
    indenter: IndenterParams | None = None,
    sensor: SensorParams | None = None,
    palpation: PalpationParams | None = None,
    relaxation: RelaxationParams | None = DEFAULT_RELAXATION,
) -> IndenterBank:
    """Builds n servo-driven 1-DOF indenters palpating Hunt-Crossley tissue.

    Args:
        n: number of indenters (one prismatic joint each).
        beta: Hunt-Crossley exponent of the tissue.
        indenter, sensor, palpation: parameters (defaults as documented).
        relaxation: the tissue's relaxation as built (its branch count is
            fixed here; the values can be changed per context with
            ``tissue.set_relaxation``); None: plain HC without state.

    Returns:
        An :class:`IndenterBank`; loggers sample at the sensor rate:
        ``state_logger`` (2n: q, v), ``force_logger`` (n, measured force,
        N), ``target_logger`` (2n: z_d, v_d), ``contact_logger`` (3n).
    """
    if int(n) != n or n < 1:
        raise VicDrakeError(f"number of indenters must be an integer >= 1, got {n!r}")
    n = int(n)
    indenter = indenter or IndenterParams()
    sensor = sensor or SensorParams()
    palpation = palpation or PalpationParams()

    builder = DiagramBuilder()
    plant = builder.AddNamedSystem(
        "plant", MultibodyPlant(time_step=indenter.time_step_s)
    )
    instance = plant.AddModelInstance("indenters")
    inertia = SpatialInertia(
        indenter.moving_mass_kg, np.zeros(3), UnitInertia.SolidSphere(0.02)
    )
    gains = PdControllerGains(
        p=indenter.servo_stiffness_N_per_m, d=indenter.servo_damping_N_s_per_m
    )
    for i in range(n):
        body = plant.AddRigidBody(f"indenter_{i}", instance, inertia)
        joint = plant.AddJoint(
            PrismaticJoint(
                f"indenter_{i}_z",
                plant.world_frame(),
                body.body_frame(),
                [0.0, 0.0, 1.0],
            )
        )
        actuator = plant.AddJointActuator(f"indenter_{i}_servo", joint)
        actuator.set_controller_gains(gains)
    plant.Finalize()

    tissue = builder.AddNamedSystem(
        "tissue", HuntCrossleyIndentation(n, beta, relaxation=relaxation)
    )
    force_sensor = builder.AddNamedSystem(
        "ft_sensor",
        LaggedForceSensor(n, sensor, indenter_mass_kg=indenter.indenter_mass_kg),
    )
    # Samples for the longest palpation simulate_palpations runs (longest
    # approach, then the palpation), and a few periods more.
    samples = (
        math.ceil((palpation.max_approach_s + palpation.duration_s) / sensor.period_s)
        + 4
    )
    noise = builder.AddNamedSystem(
        "sensor_noise", NoiseTable(n, sensor.period_s, samples)
    )
    target = builder.AddNamedSystem(
        "palpation_target", PalpationTarget(n, palpation, period_s=sensor.period_s)
    )
    gravity_compensation = builder.AddNamedSystem(
        "gravity_compensation",
        ConstantVectorSource(np.full(n, indenter.moving_mass_kg * GRAVITY_M_PER_S2)),
    )

    state_port = plant.get_state_output_port(instance)
    builder.Connect(state_port, tissue.get_indenter_state_input_port())
    builder.Connect(
        tissue.get_generalized_force_output_port(),
        plant.get_applied_generalized_force_input_port(),
    )
    builder.Connect(
        tissue.get_generalized_force_output_port(),
        force_sensor.GetInputPort("tissue_force"),
    )
    builder.Connect(
        plant.get_generalized_acceleration_output_port(instance),
        force_sensor.GetInputPort("acceleration"),
    )
    builder.Connect(noise.get_output_port(0), force_sensor.GetInputPort("noise"))
    builder.Connect(
        force_sensor.get_measured_force_output_port(),
        target.GetInputPort("measured_force"),
    )
    builder.Connect(state_port, target.GetInputPort("indenter_state"))
    builder.Connect(
        target.get_desired_state_output_port(),
        plant.get_desired_state_input_port(instance),
    )
    builder.Connect(
        gravity_compensation.get_output_port(), plant.get_actuation_input_port(instance)
    )

    period = sensor.period_s
    state_logger = LogVectorOutput(state_port, builder, period)
    force_logger = LogVectorOutput(
        force_sensor.get_measured_force_output_port(), builder, period
    )
    target_logger = LogVectorOutput(
        target.get_desired_state_output_port(), builder, period
    )
    contact_logger = LogVectorOutput(target.get_contact_output_port(), builder, period)
    for logger, name in (
        (state_logger, "state_logger"),
        (force_logger, "force_logger"),
        (target_logger, "target_logger"),
        (contact_logger, "contact_logger"),
    ):
        logger.set_name(name)
    diagram = builder.Build()
    diagram.set_name("indenter_bank")
    return IndenterBank(
        diagram=diagram,
        plant=plant,
        tissue=tissue,
        sensor=force_sensor,
        target=target,
        noise=noise,
        state_logger=state_logger,
        force_logger=force_logger,
        target_logger=target_logger,
        contact_logger=contact_logger,
        n=n,
    )


__all__ = ["IndenterBank", "MakeIndenterDiagram"]
