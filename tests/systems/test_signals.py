"""Named signals of the controller's LeafSystems: ports, layouts, one tick each.

Each system alone: ``CreateDefaultContext``, ``FixValue`` inputs, one tick
with ``EvalUniquePeriodicDiscreteUpdate``; the outputs against the pure
functions of :mod:`vic_drake.control`.
"""

import math

import numpy as np
import pytest

from vic_drake.control.params import (
    ControllerParams,
    ReferenceParams,
    StiffnessQpParams,
)
from vic_drake.control.references import force_references
from vic_drake.control.stiffness_qp.exact import solve_stiffness_qp_exact
from vic_drake.control.stiffness_qp.problem import make_stiffness_qp_problem
from vic_drake.control.tank import TankStep, tank_step
from vic_drake.systems.references import ForceReferenceSystem
from vic_drake.systems.signals import (
    CONTACT_FIELDS,
    MEASURED_FORCE,
    MEASURED_POSITION,
    MEASURED_VELOCITY,
    MEASUREMENT_SIZE,
    QP_IN_REFERENCE_TICK,
    QP_IN_TANK_ENERGY,
    QP_IN_TARGET,
    QP_INPUTS_SIZE,
    QP_TICK_ACTIVE,
    QP_TICK_DAMPING_USED,
    QP_TICK_POSITION_ERROR,
    QP_TICK_SIZE,
    QP_TICK_STIFFNESS,
    QP_TICK_VELOCITY_ERROR,
    REF_CONTACT,
    REF_FAULT,
    REF_FORCE_MIN,
    REF_FORCE_REFERENCE,
    REF_IN_CONTACT,
    REF_PENETRATION,
    REF_PROBE_POSITION,
    REF_PROBE_VELOCITY,
    REF_SURFACE_VELOCITY,
    REF_TARGET_FORCE,
    REFERENCE_TICK_SIZE,
    REFERENCES_SIZE,
    STATUS_FIELDS,
    TANK_FIELDS,
    TICK_RECORD_FIELDS,
)
from vic_drake.systems.stiffness_qp import StiffnessQpSystem
from vic_drake.systems.tank import EnergyTankSystem
from vic_drake.tissue.phantom import GridPhantom

KAPPA, LAM, BETA, SURFACE_Z = 5000.0, 40000.0, 1.35, 0.10
P_WP = np.array([0.01, -0.36, 0.095])  # 5 mm inside the tissue.
V_WP = np.array([-0.01, 0.0, 0.004])
X_D = np.array([0.0, -0.36, 0.085])
F_W = np.array([1.0, -0.5, -6.0])


@pytest.fixture(scope="module")
def phantom():
    x = np.array([-1.0, 1.0])
    ones = np.ones((2, 2))
    return GridPhantom(x_m=x, y_m=x, z_m=SURFACE_Z * ones, kappa=KAPPA * ones,
                       lam=LAM * ones, beta=BETA)  # fmt: skip


def params(controller="vs-vf"):
    return ControllerParams(
        qp=StiffnessQpParams(solver="exact"),
        reference=ReferenceParams(controller=controller),
    )


def ports(system, kind):
    n = getattr(system, f"num_{kind}_ports")()
    get = getattr(system, f"get_{kind}_port")
    return {get(i).get_name(): get(i).size() for i in range(n)}


def tick(system, context):
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))


def test_layouts_cover_their_vectors_once():
    covered = np.zeros(REFERENCES_SIZE, int)
    for part in (REF_FORCE_REFERENCE, REF_FORCE_MIN, REF_TARGET_FORCE, REF_CONTACT):
        covered[part] += 1
    assert np.all(covered == 1)
    contact = [REF_IN_CONTACT, REF_PENETRATION, REF_FAULT, REF_SURFACE_VELOCITY]
    assert [i - REF_CONTACT.start for i in contact] == list(range(len(CONTACT_FIELDS)))
    assert len(set(STATUS_FIELDS)) == 6 and len(set(TANK_FIELDS)) == 4
    covered = np.zeros(QP_TICK_SIZE, int)
    for part in (QP_TICK_POSITION_ERROR, QP_TICK_VELOCITY_ERROR, QP_TICK_STIFFNESS,
                 QP_TICK_DAMPING_USED, QP_TICK_ACTIVE):  # fmt: skip
        covered[part] += 1
    assert np.all(covered == 1)
    # The reference system's measurement: the tick record's p, v, f.
    parts = (MEASURED_POSITION, MEASURED_VELOCITY, MEASURED_FORCE)
    assert [(part.start, part.stop) for part in parts] == [(0, 3), (3, 6), (6, 9)]
    assert MEASUREMENT_SIZE == 9 and TICK_RECORD_FIELDS[6:9] == (
        "force_x_N",
        "force_y_N",
        "force_z_N",
    )
    # The QP's reference_tick: the references, then the tick record's p, v.
    record = REFERENCE_TICK_SIZE - REFERENCES_SIZE
    assert TICK_RECORD_FIELDS[:record] == ("x_m", "y_m", "z_m", "vx_m_per_s",
                                           "vy_m_per_s", "vz_m_per_s")  # fmt: skip
    assert (REF_PROBE_POSITION.start, REF_PROBE_VELOCITY.stop) == (
        REFERENCES_SIZE,
        REFERENCE_TICK_SIZE,
    )
    covered = np.zeros(QP_INPUTS_SIZE, int)
    for part in (QP_IN_TARGET, QP_IN_REFERENCE_TICK, QP_IN_TANK_ENERGY):
        covered[part] += 1
    assert np.all(covered == 1) and QP_INPUTS_SIZE == 3 + REFERENCE_TICK_SIZE + 1


def test_reference_system_ports_and_layout(phantom):
    p = params("vs-cf")
    system = ForceReferenceSystem(p, phantom=phantom)
    assert ports(system, "input") == {"measurement": MEASUREMENT_SIZE}
    assert ports(system, "output") == {
        "target_force": 3,
        "references": REFERENCES_SIZE,
        "force_reference": 3,
        "force_min": 3,
        "contact": len(CONTACT_FIELDS),
        "tick_record": len(TICK_RECORD_FIELDS),
        # The references, the record, the new filter state (3 + window 10).
        "tick": REFERENCES_SIZE + len(TICK_RECORD_FIELDS) + 13,
    }
    context = system.CreateDefaultContext()
    system.get_measurement_input_port().FixValue(
        context, np.concatenate([P_WP, V_WP, F_W])
    )
    refs = system.get_references_output_port().Eval(context)
    # The "tick" vector (what the controller Diagram hands the QP through a
    # Demultiplexer) starts with the references, then the record.
    whole = system.get_tick_output_port().Eval(context)
    np.testing.assert_array_equal(whole[:REFERENCES_SIZE], refs)
    np.testing.assert_array_equal(
        whole[REFERENCES_SIZE : REFERENCES_SIZE + len(TICK_RECORD_FIELDS)],
        [*P_WP, *V_WP, *F_W, KAPPA, LAM],
    )
    # Its head is the QP's reference_tick: the measurement the references used.
    np.testing.assert_array_equal(whole[REF_PROBE_POSITION], P_WP)
    np.testing.assert_array_equal(whole[REF_PROBE_VELOCITY], V_WP)
    expected = force_references(contact=True, kappa=KAPPA, lam=LAM, eps_dot=-V_WP[2],
                                beta=BETA, ref=p.reference, qp=p.qp)  # fmt: skip
    np.testing.assert_allclose(
        refs[REF_FORCE_REFERENCE], expected.force_ref, rtol=1e-14
    )
    np.testing.assert_allclose(refs[REF_FORCE_MIN], expected.force_min, rtol=1e-14)
    np.testing.assert_array_equal(refs[REF_TARGET_FORCE], expected.target_force)
    assert refs[REF_IN_CONTACT] == 1.0 and refs[REF_FAULT] == 0.0
    assert refs[REF_PENETRATION] == pytest.approx(SURFACE_Z - P_WP[2], rel=1e-12)
    np.testing.assert_array_equal(
        system.get_target_force_output_port().Eval(context), refs[REF_TARGET_FORCE]
    )
    tick(system, context)  # The state ports publish what the tick used.
    np.testing.assert_array_equal(
        system.get_contact_output_port().Eval(context), refs[REF_CONTACT]
    )
    np.testing.assert_array_equal(
        system.get_force_min_output_port().Eval(context), refs[REF_FORCE_MIN]
    )
    # The tick's record: what it read and the map's kappa, lambda there.
    np.testing.assert_array_equal(
        system.get_tick_record_output_port().Eval(context),
        [*P_WP, *V_WP, *F_W, KAPPA, LAM],
    )


def test_reference_system_fault_layout(phantom):
    p = params("vs-vf")
    system = ForceReferenceSystem(p, phantom=phantom)
    context = system.CreateDefaultContext()
    system.get_measurement_input_port().FixValue(
        context, np.concatenate([[0.0, math.nan, 0.1], V_WP, F_W])
    )
    refs = system.get_references_output_port().Eval(context)
    assert refs[REF_FAULT] == 1.0 and refs[REF_IN_CONTACT] == 0.0
    np.testing.assert_array_equal(refs[REF_FORCE_REFERENCE], [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(refs[REF_FORCE_MIN], [-15.0, -15.0, -15.0])


def _qp_context(system, refs, energy=0.5):
    """The QP reads x_d, the references with the probe p, v they used (the
    head of the reference system's "tick") and T, as one vector."""
    context = system.CreateDefaultContext()
    inputs = np.zeros(QP_INPUTS_SIZE)
    inputs[QP_IN_TARGET] = X_D
    inputs[QP_IN_REFERENCE_TICK] = np.concatenate([refs, P_WP, V_WP])
    inputs[QP_IN_TANK_ENERGY] = energy
    system.get_inputs_input_port().FixValue(context, inputs)
    return context


def _refs(f_ref=(0.0, 0.0, -7.0), f_min=(-15.0, -15.0, -5.0)):
    refs = np.zeros(REFERENCES_SIZE)
    refs[REF_FORCE_REFERENCE] = f_ref
    refs[REF_FORCE_MIN] = f_min
    refs[REF_IN_CONTACT] = 1.0
    refs[REF_PENETRATION] = 0.005
    return refs


def test_qp_system_publishes_what_its_tick_used():
    p = params("vs-vf")
    system = StiffnessQpSystem(p)
    assert ports(system, "input") == {"inputs": QP_INPUTS_SIZE}
    assert ports(system, "output") == {
        "stiffness": 3,
        "damping": 3,
        "qp_tick": QP_TICK_SIZE,
        "status": len(STATUS_FIELDS),
    }
    context = _qp_context(system, _refs())
    k_min = tuple(p.qp.stiffness_min_N_per_m)
    d0 = [2 * 0.707 * math.sqrt(k) for k in k_min]
    # Before the first tick: K_min, no tick for the tank.
    record = system.get_qp_tick_output_port().Eval(context)
    assert record[QP_TICK_ACTIVE] == 0.0
    np.testing.assert_array_equal(
        system.get_stiffness_output_port().Eval(context), k_min
    )
    np.testing.assert_array_equal(record[QP_TICK_STIFFNESS], k_min)
    np.testing.assert_allclose(record[QP_TICK_DAMPING_USED], d0, rtol=1e-15)
    tick(system, context)
    e, e_dot = tuple(X_D - P_WP), tuple(-V_WP)
    problem = make_stiffness_qp_problem(e, e_dot, d0, (0, 0, -7.0), (-15, -15, -5.0),
                                        0.5, p.period_s, p.qp, p.tank)  # fmt: skip
    k = solve_stiffness_qp_exact(problem).stiffness
    np.testing.assert_allclose(system.get_stiffness_output_port().Eval(context), k,
                               rtol=0, atol=1e-12)  # fmt: skip
    record = system.get_qp_tick_output_port().Eval(context)
    np.testing.assert_array_equal(record[QP_TICK_POSITION_ERROR], e)
    np.testing.assert_array_equal(record[QP_TICK_VELOCITY_ERROR], e_dot)
    np.testing.assert_array_equal(
        record[QP_TICK_STIFFNESS], system.get_stiffness_output_port().Eval(context)
    )
    np.testing.assert_allclose(record[QP_TICK_DAMPING_USED], d0, rtol=1e-15)
    assert record[QP_TICK_ACTIVE] == 1.0
    status = dict(zip(STATUS_FIELDS, system.get_status_output_port().Eval(context)))
    assert status["qp_ok"] == 1.0 and status["in_contact"] == 1.0
    assert status["penetration_m"] == 0.005 and status["fallback_count"] == 0.0


def test_qp_system_constant_stiffness_is_no_tank_tick():
    system = StiffnessQpSystem(params("cs"))
    context = _qp_context(system, _refs())
    tick(system, context)
    record = system.get_qp_tick_output_port().Eval(context)
    assert record[QP_TICK_ACTIVE] == 0.0
    np.testing.assert_array_equal(record[QP_TICK_POSITION_ERROR], [0.0, 0.0, 0.0])


def test_qp_system_fault_flag_from_the_references():
    system = StiffnessQpSystem(params("vs-vf"))
    refs = _refs()
    refs[REF_FAULT] = 1.0
    context = _qp_context(system, refs)
    tick(system, context)
    status = dict(zip(STATUS_FIELDS, system.get_status_output_port().Eval(context)))
    assert status["fault"] == 1.0 and status["qp_ok"] == 0.0
    assert status["in_contact"] == 0.0 and status["fallback_count"] == 1.0


def _tank_context(system, e, e_dot, k, d, active):
    context = system.CreateDefaultContext()
    record = np.zeros(QP_TICK_SIZE)
    record[QP_TICK_POSITION_ERROR] = e
    record[QP_TICK_VELOCITY_ERROR] = e_dot
    record[QP_TICK_STIFFNESS] = k
    record[QP_TICK_DAMPING_USED] = d
    record[QP_TICK_ACTIVE] = active
    system.get_qp_tick_input_port().FixValue(context, record)
    return context


def test_tank_system_ports_and_one_tick():
    p = params("vs-vf")
    system = EnergyTankSystem(p)
    assert ports(system, "input") == {"qp_tick": QP_TICK_SIZE}
    assert ports(system, "output") == {
        "x_t": 1,
        "tank": len(TANK_FIELDS),
        "tank_energy": 1,
    }
    e, e_dot, k, d = (
        (0.0, 0.0, -0.01),
        (0.0, 0.0, 0.02),
        (300.0, 300.0, 600.0),
        (24.0, 24.0, 30.0),
    )
    context = _tank_context(system, e, e_dot, k, d, 1.0)
    k_min = tuple(p.qp.stiffness_min_N_per_m)
    step = tank_step(0.5, e, e_dot, k, k_min, d, p.period_s, p.tank)
    tank = dict(zip(TANK_FIELDS, system.get_tank_output_port().Eval(context)))
    assert tank == {"T_J": step.energy_J, "power_W": step.power_W,
                    "sigma": step.sigma, "enabled": 1.0}  # fmt: skip
    assert system.get_energy_output_port().Eval(context)[0] == step.energy_J
    tick(system, context)
    x_t = system.GetOutputPort("x_t").Eval(context)[0]
    assert 0.5 * x_t * x_t == pytest.approx(step.energy_J, rel=1e-14)


def test_tank_system_inactive_tick_keeps_the_energy():
    p = params("cs")
    system = EnergyTankSystem(p)
    context = _tank_context(
        system, (0.01,) * 3, (0.02,) * 3, (400.0,) * 3, (28.0,) * 3, 0.0
    )
    expected = TankStep(0.5, 0.0, 0.0, False)
    np.testing.assert_array_equal(system.get_tank_output_port().Eval(context),
                                  [expected.energy_J, 0.0, 0.0, 0.0])  # fmt: skip
