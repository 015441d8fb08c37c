"""The controller Diagram and its LeafSystems: ports, one tick, faults, parameters."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.systems.analysis import Simulator

from vic_drake.control.params import (
    ControllerParams,
    ReferenceParams,
    StiffnessQpParams,
    TankParams,
)
from vic_drake.control.stiffness_qp.exact import solve_stiffness_qp_exact
from vic_drake.control.stiffness_qp.problem import make_stiffness_qp_problem
from vic_drake.control.tank import tank_step
from vic_drake.errors import VicDrakeError
from vic_drake.systems.controller import MakeVariableImpedanceController
from vic_drake.systems.references import ForceReferenceSystem
from vic_drake.systems.signals import (
    QP_IN_REFERENCE_TICK,
    QP_IN_TANK_ENERGY,
    QP_IN_TARGET,
    REF_PROBE_POSITION,
    REF_PROBE_VELOCITY,
)
from vic_drake.systems.stiffness_qp import StiffnessQpSystem
from vic_drake.systems.tank import EnergyTankSystem
from vic_drake.tissue.phantom import GridPhantom

KAPPA, LAM, BETA, SURFACE_Z = 5000.0, 40000.0, 1.35, 0.10


@pytest.fixture(scope="module")
def phantom():
    """Flat tissue at z = 0.10 m with uniform kappa, lambda."""
    x = np.array([-1.0, 1.0])
    ones = np.ones((2, 2))
    return GridPhantom(
        x_m=x,
        y_m=x,
        z_m=SURFACE_Z * ones,
        kappa=KAPPA * ones,
        lam=LAM * ones,
        beta=BETA,
    )


P_WP = np.array([0.01, -0.36, 0.095])  # 5 mm inside the tissue.
V_WP = np.array([-0.01, 0.0, 0.004])
X_D = np.array([0.0, -0.36, 0.085])
F_W = np.array([1.0, -0.5, -6.0])


def make(phantom, controller="vs-cf", **kw):
    """The Diagram with fixed inputs; the exact solver unless qp= is given,
    so that ticks can be compared with the pure functions to 1e-12."""
    kw.setdefault("qp", StiffnessQpParams(solver="exact"))
    params = ControllerParams(reference=ReferenceParams(controller=controller), **kw)
    diagram = MakeVariableImpedanceController(params, phantom=phantom)
    context = diagram.CreateDefaultContext()
    for name, value in (("probe.position", P_WP), ("probe.velocity", V_WP), ("target_position", X_D),
                        ("ft_sensor.force_W", F_W)):  # fmt: skip
        diagram.GetInputPort(name).FixValue(context, value)
    return params, diagram, context


def tick(diagram, context, n=1):
    for _ in range(n):
        context.SetDiscreteState(diagram.EvalUniquePeriodicDiscreteUpdate(context))


def out(diagram, context, name):
    return diagram.GetOutputPort(name).Eval(context)


def test_ports_match_the_interface(phantom):
    _, diagram, _ = make(phantom)
    assert diagram.get_name() == "variable_impedance_controller"
    inputs = {diagram.get_input_port(i).get_name(): diagram.get_input_port(i).size()
              for i in range(diagram.num_input_ports())}  # fmt: skip
    outputs = {diagram.get_output_port(i).get_name(): diagram.get_output_port(i).size()
               for i in range(diagram.num_output_ports())}  # fmt: skip
    assert inputs == {
        "probe.position": 3,
        "probe.velocity": 3,
        "target_position": 3,
        "ft_sensor.force_W": 3,
    }
    assert outputs == {"stiffness": 3, "damping": 3, "target_force": 3, "force_reference": 3,
                       "force_min": 3, "tank": 4, "status": 6, "contact": 4,
                       "tick_record": 11}  # fmt: skip


def test_one_tick_equals_the_pure_functions(phantom):
    params, diagram, context = make(phantom, "vs-cf")
    k0 = tuple(params.qp.stiffness_min_N_per_m)
    np.testing.assert_array_equal(out(diagram, context, "stiffness"), k0)
    tick(diagram, context)
    # Independent computation of the same tick.
    e = tuple(X_D - P_WP)
    e_dot = tuple(-V_WP)
    d0 = tuple(2 * 0.707 * math.sqrt(k) for k in k0)
    eps_dot = 0.0 - V_WP[2]  # Flat surface: first filter tick gives rate 0.
    f_min_z = -(KAPPA + LAM * eps_dot) * 0.008**BETA
    problem = make_stiffness_qp_problem(e, e_dot, d0, (0, 0, -7.0), (-15, -15, f_min_z), 0.5, 0.002,
                                        params.qp, params.tank)  # fmt: skip
    expected = solve_stiffness_qp_exact(problem)
    assert expected.success
    np.testing.assert_allclose(
        out(diagram, context, "stiffness"), expected.stiffness, rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(out(diagram, context, "damping"),
                               2 * 0.707 * np.sqrt(expected.stiffness), rtol=1e-14)  # fmt: skip
    np.testing.assert_allclose(
        out(diagram, context, "force_min"), (-15, -15, f_min_z), rtol=1e-14
    )
    np.testing.assert_array_equal(
        out(diagram, context, "force_reference"), (0, 0, -7.0)
    )
    np.testing.assert_array_equal(out(diagram, context, "target_force"), (0, 0, 0))
    step = tank_step(0.5, e, e_dot, expected.stiffness, k0, d0, 0.002, params.tank)
    np.testing.assert_allclose(out(diagram, context, "tank"), [step.energy_J, step.power_W, 1.0, 1.0],
                               rtol=1e-14)  # fmt: skip
    qp_ok, count, fault, contact, solve_time, pen = out(diagram, context, "status")
    assert (qp_ok, count, fault, contact) == (1.0, 0.0, 0.0, 1.0)
    assert solve_time > 0.0 and pen == pytest.approx(SURFACE_Z - P_WP[2])


def test_tank_and_qp_stay_in_step_over_many_ticks(phantom):
    """No one-tick lag: the QP sees T after the previous tick, the tank applies this tick's K."""
    params, diagram, context = make(phantom, "vs-vf")
    energy, k_prev = 0.5, tuple(params.qp.stiffness_min_N_per_m)
    k_min = k_prev
    for _ in range(5):
        tick(diagram, context)
        d = tuple(2 * 0.707 * math.sqrt(k) for k in k_prev)
        f_ref = out(diagram, context, "force_reference")
        f_min = out(diagram, context, "force_min")
        p = make_stiffness_qp_problem(tuple(X_D - P_WP), tuple(-V_WP), d, f_ref, f_min, energy, 0.002,
                                      params.qp, params.tank)  # fmt: skip
        k = solve_stiffness_qp_exact(p).stiffness
        energy = tank_step(
            energy, tuple(X_D - P_WP), tuple(-V_WP), k, k_min, d, 0.002, params.tank
        ).energy_J
        np.testing.assert_allclose(
            out(diagram, context, "stiffness"), k, atol=1e-12, rtol=0
        )
        assert out(diagram, context, "tank")[0] == pytest.approx(energy, rel=1e-14)
        k_prev = k


@pytest.mark.parametrize(
    "port", ["probe.position", "probe.velocity", "target_position", "ft_sensor.force_W"]
)
@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_non_finite_measurement_gives_k_min_and_fault(phantom, port, bad):
    params, diagram, context = make(phantom, "vs-vf")
    tick(diagram, context, 3)
    value = {
        "probe.position": P_WP,
        "probe.velocity": V_WP,
        "target_position": X_D,
        "ft_sensor.force_W": F_W,
    }[port].copy()
    value[2] = bad
    diagram.GetInputPort(port).FixValue(context, value)
    tick(diagram, context, 2)
    np.testing.assert_array_equal(
        out(diagram, context, "stiffness"), params.qp.stiffness_min_N_per_m
    )
    status = out(diagram, context, "status")
    assert status[0] == 0.0 and status[1] == 2.0 and status[2] == 1.0
    for i in range(diagram.num_output_ports()):
        name = diagram.get_output_port(i).get_name()
        if name == "tick_record":  # A log of what the tick read: the bad value.
            record = diagram.get_output_port(i).Eval(context)
            if port != "target_position":  # Not an input of the references.
                assert bad in record or (math.isnan(bad) and np.isnan(record).any())
            continue
        assert np.all(np.isfinite(diagram.get_output_port(i).Eval(context))), name
    diagram.GetInputPort(port).FixValue(context, {"probe.position": P_WP, "probe.velocity": V_WP,
                                                  "target_position": X_D, "ft_sensor.force_W": F_W}[port])  # fmt: skip
    tick(diagram, context)
    assert out(diagram, context, "status")[2] == 0.0  # Recovers; the count stays.
    assert out(diagram, context, "status")[1] == 2.0


def test_cs_and_cf(phantom):
    params, diagram, context = make(phantom, "cs")
    tick(diagram, context, 3)
    np.testing.assert_array_equal(out(diagram, context, "stiffness"), [400.0] * 3)
    np.testing.assert_array_equal(out(diagram, context, "target_force"), [0.0] * 3)
    np.testing.assert_array_equal(out(diagram, context, "tank"), [0.5, 0.0, 0.0, 0.0])
    params, diagram, context = make(phantom, "cf")
    tick(diagram, context, 3)
    np.testing.assert_array_equal(
        out(diagram, context, "stiffness"), [400.0, 400.0, 0.0]
    )
    np.testing.assert_array_equal(out(diagram, context, "damping")[2], 0.0)
    np.testing.assert_array_equal(
        out(diagram, context, "target_force"), [0.0, 0.0, -7.0]
    )
    assert out(diagram, context, "status")[0] == 1.0


def test_target_force_is_cf_only_and_zero_on_a_fault(phantom):
    _, diagram, context = make(phantom, "cf")
    diagram.GetInputPort("probe.velocity").FixValue(context, [0.0, math.nan, 0.0])
    np.testing.assert_array_equal(out(diagram, context, "target_force"), [0.0] * 3)
    diagram.GetInputPort("probe.velocity").FixValue(context, V_WP)
    np.testing.assert_array_equal(
        out(diagram, context, "target_force"), [0.0, 0.0, -7.0]
    )
    for controller in ("cs", "vs-cf", "vs-vf"):  # A constant zero, no feedthrough.
        params = ControllerParams(reference=ReferenceParams(controller=controller))
        system = ForceReferenceSystem(params, phantom=phantom)
        port = system.get_target_force_output_port()
        assert not any(
            system.HasDirectFeedthrough(i, port.get_index())
            for i in range(system.num_input_ports())
        )
        context = system.CreateDefaultContext()
        system.get_measurement_input_port().FixValue(
            context, np.concatenate([P_WP, V_WP, F_W])
        )
        np.testing.assert_array_equal(port.Eval(context), [0.0] * 3)


def test_qp_reads_the_tanks_energy(phantom):
    _, diagram, context = make(phantom, "vs-vf")
    qp = diagram.GetSubsystemByName("stiffness_qp")
    tank = diagram.GetSubsystemByName("energy_tank")
    for _ in range(3):
        tick(diagram, context)
        np.testing.assert_array_equal(
            qp.get_inputs_input_port().Eval(qp.GetMyContextFromRoot(context))[
                QP_IN_TANK_ENERGY : QP_IN_TANK_ENERGY + 1
            ],
            tank.get_energy_output_port().Eval(tank.GetMyContextFromRoot(context)),
        )


def test_qp_reads_the_probe_state_the_references_used(phantom):
    """The QP's p, v are the head of the reference tick's record: the Diagram's
    probe inputs, also after they change; its x_d is the Diagram's input."""
    _, diagram, context = make(phantom, "vs-vf")
    qp = diagram.GetSubsystemByName("stiffness_qp")
    p2, v2 = P_WP + [0.001, -0.002, 0.0005], V_WP + [0.003, 0.0, -0.001]
    for p, v in ((P_WP, V_WP), (p2, v2)):
        diagram.GetInputPort("probe.position").FixValue(context, p)
        diagram.GetInputPort("probe.velocity").FixValue(context, v)
        inputs = qp.get_inputs_input_port().Eval(qp.GetMyContextFromRoot(context))
        np.testing.assert_array_equal(inputs[QP_IN_TARGET], X_D)
        head = inputs[QP_IN_REFERENCE_TICK]
        np.testing.assert_array_equal(head[REF_PROBE_POSITION], p)
        np.testing.assert_array_equal(head[REF_PROBE_VELOCITY], v)
        tick(diagram, context)
        record = out(diagram, context, "tick_record")
        np.testing.assert_array_equal(record[:6], [*p, *v])


def test_osqp_system_matches_exact_system(phantom):
    _, exact, c1 = make(phantom, "vs-vf")
    _, osqp, c2 = make(phantom, "vs-vf", qp=StiffnessQpParams())  # Default: OSQP.
    tick(exact, c1, 4)
    tick(osqp, c2, 4)
    np.testing.assert_allclose(
        out(osqp, c2, "stiffness"), out(exact, c1, "stiffness"), atol=1e-6, rtol=0
    )


def test_simulator_runs_the_periodic_events(phantom):
    params, diagram, context = make(phantom, "vs-vf")
    simulator = Simulator(diagram, context)
    simulator.AdvanceTo(0.1)
    tank = out(diagram, context, "tank")
    assert tank[0] != 0.5  # 51 ticks of nonzero power changed the tank.
    assert np.all(np.isfinite(tank))


def _mutated(path, value):
    params = ControllerParams()
    owner = params
    *head, last = path.split(".")
    for name in head:
        owner = getattr(owner, name)
    setattr(owner, last, value)  # As yaml_load_typed does after __init__.
    return params


@pytest.mark.parametrize(
    "path, value, shown",
    [
        ("period_s", 0.0, "0.0"),
        ("period_s", -0.002, "-0.002"),
        ("period_s", math.nan, "nan"),
        ("tank.min_energy_J", 0.0, "0.0"),
        ("tank.power_limit_W", 0.05, "0.05"),
        ("tank.power_limit_W", 0.0, "0.0"),
        ("qp.r_weight", [0.1, math.nan, 0.1], "nan"),
        ("reference.controller", "impedance", "impedance"),
    ],
)
def test_invalid_parameters_fail_at_construction(phantom, path, value, shown):
    params = _mutated(path, value)
    with pytest.raises(VicDrakeError) as info:
        MakeVariableImpedanceController(params, phantom=phantom)
    message = str(info.value)
    assert path.split(".")[-1] in message and shown in message


def test_values_mutated_after_construction_are_checked(phantom):
    params = ControllerParams()
    params.qp.stiffness_min_N_per_m = [300.0, 300.0, 2000.0]  # As YAML loading would.
    for build in (lambda: MakeVariableImpedanceController(params, phantom=phantom),
                  lambda: StiffnessQpSystem(params), lambda: EnergyTankSystem(params),
                  lambda: ForceReferenceSystem(params, phantom=phantom)):  # fmt: skip
        with pytest.raises(VicDrakeError, match=r"stiffness_min_N_per_m\[2\] = 2000.0"):
            build()


@pytest.fixture(scope="module")
def sloped():
    """Tissue surface z = 0.10 + 0.2 x (slope 0.2 along x), uniform kappa, lambda."""
    x = np.array([-1.0, 1.0])
    z = 0.10 + 0.2 * np.array([[-1.0, -1.0], [1.0, 1.0]])
    ones = np.ones((2, 2))
    return GridPhantom(
        x_m=x, y_m=x, z_m=z, kappa=KAPPA * ones, lam=LAM * ones, beta=BETA
    )


def test_surface_velocity_moving_average_in_the_system(sloped):
    params, diagram, context = make(sloped, "vs-cf")
    tick(diagram, context)  # Records the height under P_WP.
    p2 = P_WP + np.array([-0.001, 0.0, 0.0])  # 1 mm along -x: surface 0.2 mm lower.
    diagram.GetInputPort("probe.position").FixValue(context, p2)
    tick(diagram, context)  # The state ports publish what this tick used.
    ref = diagram.GetSubsystemByName("force_reference")
    contact = ref.get_contact_output_port().Eval(ref.GetMyContextFromRoot(context))
    z_rate = (0.2 * -0.001) / 0.002  # One finite difference, averaged over 10 samples.
    assert contact[3] == pytest.approx(z_rate / 10, rel=1e-9)
    eps_dot = contact[3] - V_WP[2]
    f_min_z = -(KAPPA + LAM * eps_dot) * 0.008**BETA
    assert out(diagram, context, "force_min")[2] == pytest.approx(f_min_z, rel=1e-12)


def test_surface_velocity_gradient_mode(sloped):
    params = ControllerParams(
        reference=ReferenceParams(controller="vs-vf", surface_velocity_mode="gradient")
    )
    diagram = MakeVariableImpedanceController(params, phantom=sloped)
    context = diagram.CreateDefaultContext()
    for name, value in (("probe.position", P_WP), ("probe.velocity", V_WP), ("target_position", X_D),
                        ("ft_sensor.force_W", F_W)):  # fmt: skip
        diagram.GetInputPort(name).FixValue(context, value)
    eps_dot = 0.2 * V_WP[0] - V_WP[2]  # grad z . v minus z_dot.
    f_ref_z = -(KAPPA + LAM * eps_dot) * 0.008**BETA
    tick(diagram, context)
    assert out(diagram, context, "force_reference")[2] == pytest.approx(
        f_ref_z, rel=1e-12
    )


def test_built_diagram_ignores_later_edits_of_its_params(phantom):
    params, diagram, context = make(phantom, "vs-vf")
    params.qp.stiffness_min_N_per_m[2] = 900.0  # After building: no effect.
    params.reference.controller = "cs"
    tick(diagram, context)
    k = out(diagram, context, "stiffness")
    assert k[2] < 900.0 and not np.allclose(k, 400.0)


_step = st.tuples(
    st.tuples(
        st.floats(-0.004, 0.004), st.floats(-0.004, 0.004), st.floats(-0.004, 0.004)
    ),
    st.tuples(st.floats(-0.05, 0.05), st.floats(-0.05, 0.05), st.floats(-0.05, 0.05)),
    st.floats(-12.0, 1.0),
)


@settings(max_examples=25, deadline=None)
@given(steps=st.lists(_step, min_size=5, max_size=30), energy=st.floats(0.41, 0.6),
       controller=st.sampled_from(["vs-cf", "vs-vf"]))  # fmt: skip
def test_random_closed_sequences_keep_tank_and_bounds(
    phantom, steps, energy, controller
):
    """Any measurement sequence: T >= T_min and K_min <= K <= K_max at every tick."""
    params = ControllerParams(
        qp=StiffnessQpParams(solver="exact", r_weight=[1e-5] * 3),
        tank=TankParams(initial_energy_J=energy),
        reference=ReferenceParams(controller=controller),
    )
    diagram = MakeVariableImpedanceController(params, phantom=phantom)
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort("target_position").FixValue(context, X_D)
    p = P_WP.copy()
    k_lo, k_hi = (
        np.array(params.qp.stiffness_min_N_per_m),
        np.array(params.qp.stiffness_max_N_per_m),
    )
    for dp, v, fz in steps:
        p = p + np.array(dp)
        diagram.GetInputPort("probe.position").FixValue(context, p)
        diagram.GetInputPort("probe.velocity").FixValue(context, np.array(v))
        diagram.GetInputPort("ft_sensor.force_W").FixValue(context, [0.0, 0.0, fz])
        tick(diagram, context)
        tank = out(diagram, context, "tank")
        k = out(diagram, context, "stiffness")
        assert tank[0] >= params.tank.min_energy_J - 1e-12
        assert (
            tank[1] >= params.tank.power_limit_W - 1e-9
        )  # Power valve, also on fallbacks.
        assert np.all(k >= k_lo - 1e-9) and np.all(k <= k_hi + 1e-9)
        assert np.all(np.isfinite(out(diagram, context, "damping")))
