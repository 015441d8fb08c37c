"""The Hunt-Crossley force element at the probe tip."""

import numpy as np
import pytest
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.tree import BodyIndex

from vic_drake.systems.tissue_force import (
    SAMPLE_FIELDS,
    TissueForceElement,
    tip_contact,
)
from vic_drake.tissue import GridPhantom, PointLookup, hunt_crossley_force


def _plane_phantom(z0=0.1, gx=0.2, gy=-0.1, kappa=3000.0, lam=30000.0):
    """A tilted plane z = z0 + gx x + gy y with uniform kappa, lambda."""
    xs = np.linspace(-0.2, 0.2, 41)
    ys = np.linspace(-0.2, 0.2, 41)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    return GridPhantom(
        x_m=xs,
        y_m=ys,
        z_m=z0 + gx * X + gy * Y,
        kappa=np.full(X.shape, kappa),
        lam=np.full(X.shape, lam),
        beta=1.35,
    )


def test_penetration_and_force_match_the_law():
    ph = _plane_phantom()
    p = np.array([0.01, -0.02, 0.09])
    v = np.array([0.01, 0.02, -0.03])
    c = tip_contact(ph, p, v)
    surface = 0.1 + 0.2 * 0.01 - 0.1 * -0.02
    assert c.surface_z_m == pytest.approx(surface, abs=1e-12)
    assert c.penetration_m == pytest.approx(surface - 0.09, abs=1e-12)
    eps_dot = 0.2 * 0.01 - 0.1 * 0.02 + 0.03
    assert c.penetration_rate_m_per_s == pytest.approx(eps_dot, abs=1e-12)
    expected = hunt_crossley_force(c.penetration_m, eps_dot, 3000.0, 30000.0, 1.35)
    assert c.force_N == pytest.approx(float(expected), rel=1e-12)


def test_penetration_rate_is_the_time_derivative_with_a_moving_phantom():
    ph = _plane_phantom()
    p0, v = np.array([0.0, 0.01, 0.095]), np.array([0.02, -0.01, -0.004])
    lift0, lift_v = np.array([0.0, 0.0, 0.003]), np.array([0.0, 0.0, 0.05])
    h = 1e-6
    c0 = tip_contact(ph, p0, v, lift0, lift_v)
    c1 = tip_contact(ph, p0 + h * v, v, lift0 + h * lift_v, lift_v)
    fd = (c1.penetration_m - c0.penetration_m) / h
    assert c0.penetration_rate_m_per_s == pytest.approx(fd, rel=1e-6)


def test_no_force_out_of_contact_and_no_pull():
    ph = _plane_phantom()
    above = tip_contact(ph, [0, 0, 0.11], [0, 0, 0])
    assert above.force_N == 0.0 and above.penetration_m < 0
    # Retracting fast: the raw law would pull; the element never does.
    retract = tip_contact(ph, [0, 0, 0.099], [0, 0, 1.0])
    assert retract.penetration_m > 0 and retract.force_N == 0.0


def test_system_applies_force_at_tip_and_reaction_on_phantom():
    ph = _plane_phantom(gx=0.0, gy=0.0)
    p_BT = np.array([0.0, 0.0, 0.07])
    system = TissueForceElement(
        ph, indenter_body_index=BodyIndex(1), p_BT=p_BT, phantom_body_index=BodyIndex(2)
    )
    context = system.CreateDefaultContext()
    X_WB = RigidTransform(
        RotationMatrix.MakeXRotation(np.pi), [0.01, 0.02, 0.09 + 0.07]
    )
    # Tool pointing down: tip at z = 0.09, 1 cm deep.
    poses = [RigidTransform(), X_WB, RigidTransform([0, 0, 0.0])]
    vels = [SpatialVelocity.Zero()] * 3
    system.get_body_poses_input_port().FixValue(context, poses)
    system.get_body_spatial_velocities_input_port().FixValue(context, vels)
    forces = system.get_spatial_forces_output_port().Eval(context)
    expected = float(hunt_crossley_force(0.01, 0.0, 3000.0, 30000.0, 1.35))
    assert system.get_penetration_output_port().Eval(context)[0] == pytest.approx(0.01)
    np.testing.assert_allclose(
        system.get_force_output_port().Eval(context), [0, 0, expected]
    )
    on_tip, on_phantom = forces
    assert int(on_tip.body_index) == 1 and int(on_phantom.body_index) == 2
    np.testing.assert_allclose(on_tip.p_BoBq_B, p_BT)
    np.testing.assert_allclose(on_tip.F_Bq_W.translational(), [0, 0, expected])
    np.testing.assert_allclose(on_phantom.F_Bq_W.translational(), [0, 0, -expected])
    np.testing.assert_allclose(on_phantom.p_BoBq_B, [0.01, 0.02, 0.09])
    # The tip's kinematics, exported by the station as probe.position/velocity.
    np.testing.assert_allclose(
        system.get_tip_position_output_port().Eval(context), [0.01, 0.02, 0.09]
    )
    np.testing.assert_allclose(
        system.get_tip_velocity_output_port().Eval(context), [0, 0, 0]
    )
    # A second context (2 mm deeper) does not alter the first one's forces.
    other = system.CreateDefaultContext()
    deeper = RigidTransform(X_WB.rotation(), X_WB.translation() - [0, 0, 0.002])
    system.get_body_poses_input_port().FixValue(other, [poses[0], deeper, poses[2]])
    system.get_body_spatial_velocities_input_port().FixValue(other, vels)
    second = system.get_spatial_forces_output_port().Eval(other)
    assert second[0].F_Bq_W.translational()[2] > expected
    again = system.get_spatial_forces_output_port().Eval(context)
    np.testing.assert_allclose(again[0].F_Bq_W.translational(), [0, 0, expected])
    np.testing.assert_allclose(on_tip.F_Bq_W.translational(), [0, 0, expected])


def test_grid_lookup_equals_the_grid_phantom():
    rng = np.random.default_rng(0)
    xs = np.linspace(-0.1, 0.05, 31)
    ys = np.linspace(-0.4, -0.3, 21)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    for lookup in ("bilinear", "nearest"):
        ph = GridPhantom(
            x_m=xs,
            y_m=ys,
            z_m=0.1 + 0.02 * np.sin(40 * X) * np.cos(30 * Y),
            kappa=3000 + 500 * np.cos(50 * X),
            lam=2e4 + 1e3 * np.sin(20 * Y),
            lookup=lookup,
        )
        fast = PointLookup(ph)
        # Inside, on nodes, and outside the grid (clamped, zero gradient across).
        pts = np.concatenate(
            [
                rng.uniform([-0.12, -0.42], [0.07, -0.28], (200, 2)),
                np.stack(np.meshgrid(xs[::7], ys[::5]), -1).reshape(-1, 2),
            ]
        )
        for x, y in pts:
            a, b = ph.sample(x, y), fast.sample(x, y)
            for name in ("surface_z_m", "dz_dx", "dz_dy", "kappa", "lam"):
                assert getattr(b, name) == pytest.approx(
                    float(getattr(a, name)), rel=1e-12, abs=1e-12
                ), (lookup, name, x, y)


def test_grid_lookup_of_the_synthetic_chest_is_close():
    from vic_drake.tissue import SyntheticChestPhantom

    ph = SyntheticChestPhantom()
    fast = PointLookup(ph, resolution_m=0.0005)
    rng = np.random.default_rng(1)
    for x, y in rng.uniform([-0.2, -0.5], [0.08, -0.2], (100, 2)):
        a, b = ph.sample(x, y), fast.sample(x, y)
        assert b.surface_z_m == pytest.approx(float(a.surface_z_m), abs=2e-6)
        assert b.kappa == pytest.approx(float(a.kappa), rel=5e-3)
        assert b.lam == pytest.approx(float(a.lam), rel=1e-2)
        assert b.dz_dx == pytest.approx(float(a.dz_dx), abs=1e-3)


def test_optional_friction_opposes_sliding_and_scales_with_the_normal_force():
    ph = _plane_phantom(gx=0.0, gy=0.0)
    v = np.array([-0.01, 0.0, 0.0])  # sliding along -x at 1 cm/s
    none = tip_contact(ph, [0, 0, 0.09], v)
    assert none.friction_x_N == 0.0 and none.friction_y_N == 0.0
    c = tip_contact(
        ph, [0, 0, 0.09], v, friction_coefficient=0.3, slip_speed_m_per_s=1e-4
    )
    assert c.friction_x_N == pytest.approx(0.3 * c.force_N, rel=1e-3)
    assert c.friction_y_N == 0.0
    off = tip_contact(ph, [0, 0, 0.11], v, friction_coefficient=0.3)
    assert off.friction_x_N == 0.0


def test_optional_force_along_the_surface_normal():
    ph = _plane_phantom(gx=0.2, gy=-0.1)
    vertical = tip_contact(ph, [0.0, 0.0, 0.09], np.zeros(3))
    normal = tip_contact(ph, [0.0, 0.0, 0.09], np.zeros(3), along_normal=True)
    assert normal.force_N == vertical.force_N > 0
    np.testing.assert_allclose(
        normal.force_W, vertical.force_N * np.array([-0.2, 0.1, 1.0])
    )
    np.testing.assert_allclose(vertical.force_W, [0.0, 0.0, vertical.force_N])


def test_ports_carry_the_station_signal_names():
    """One name per signal: the element's ports are named as the station exports them."""
    system = TissueForceElement(
        _plane_phantom(),
        indenter_body_index=BodyIndex(1),
        p_BT=np.zeros(3),
        phantom_body_index=BodyIndex(2),
    )
    outputs = {system.get_output_port(i).get_name(): system.get_output_port(i).size()
               for i in range(system.num_output_ports())
               if system.get_output_port(i).get_data_type().name == "kVectorValued"}  # fmt: skip
    assert outputs == {
        "tissue.force_W": 3,
        "tissue.penetration": 1,
        "tissue.surface_z": 1,
        "probe.position": 3,
        "probe.velocity": 3,
        "tissue.sample": len(SAMPLE_FIELDS),
    }
    assert system.get_force_output_port().get_name() == "tissue.force_W"
    assert system.get_tip_position_output_port().get_name() == "probe.position"
    assert system.get_tip_velocity_output_port().get_name() == "probe.velocity"


def test_relaxing_element_decays_like_the_prony_series():
    """A held tip: the force relaxes as kappa u G(t) tick by tick; HC without."""
    from vic_drake.tissue import RelaxationParams

    ph = _plane_phantom(gx=0.0, gy=0.0)
    relaxation = RelaxationParams(fractions=(0.1, 0.2), time_constants_s=(0.05, 1.0))
    system = TissueForceElement(
        ph,
        indenter_body_index=BodyIndex(1),
        p_BT=np.array([0.0, 0.0, 0.07]),
        phantom_body_index=BodyIndex(2),
        relaxation=relaxation,
        update_period_s=0.002,
    )
    context = system.CreateDefaultContext()
    X_WB = RigidTransform(RotationMatrix.MakeXRotation(np.pi), [0.0, 0.0, 0.09 + 0.07])
    system.get_body_poses_input_port().FixValue(
        context, [RigidTransform(), X_WB, RigidTransform()]
    )
    system.get_body_spatial_velocities_input_port().FixValue(
        context, [SpatialVelocity.Zero()] * 3
    )
    hc = float(hunt_crossley_force(0.01, 0.0, 3000.0, 30000.0, 1.35))
    assert system.get_force_output_port().Eval(context)[2] == pytest.approx(hc)
    for k in range(1, 501):
        update = system.EvalUniquePeriodicDiscreteUpdate(context)
        context.get_mutable_discrete_state().SetFrom(update)
        if k % 100 == 0:
            force = system.get_force_output_port().Eval(context)[2]
            expected = hc * float(relaxation.relaxation_function(k * 0.002))
            assert force == pytest.approx(expected, rel=1e-12)
    forces = system.get_spatial_forces_output_port().Eval(context)
    assert forces[0].F_Bq_W.translational()[2] == pytest.approx(expected, rel=1e-12)
    plain = TissueForceElement(
        ph,
        indenter_body_index=BodyIndex(1),
        p_BT=np.array([0.0, 0.0, 0.07]),
        phantom_body_index=BodyIndex(2),
    )
    assert plain.get_relaxation_state_index() is None
    # Only the sample and its tick: no branch states.
    assert plain.CreateDefaultContext().num_discrete_state_groups() == 2


def test_the_stored_sample_is_the_contact_the_next_plant_step_uses():
    """In a scan, the state the tick stores equals the live contact at the next step.

    The element relies on the plant stepping in an unrestricted update, before
    the discrete updates of the same tick (the plant's sampled output ports);
    if Drake ever orders them otherwise, this fails.
    """
    from pydrake.systems.analysis import Simulator

    from vic_drake.experiments import synthetic_scenario
    from vic_drake.experiments.scan_diagram import (
        MakeScanDiagram,
        initial_joint_positions,
        set_initial_state,
    )

    scenario = synthetic_scenario("vs-vf")
    diagram, _ = MakeScanDiagram(scenario)
    simulator = Simulator(diagram)
    root = simulator.get_mutable_context()
    set_initial_state(diagram, root, initial_joint_positions(scenario))
    simulator.Initialize()
    station = diagram.GetSubsystemByName("station")
    element = station.GetSubsystemByName("tissue_force")
    context = element.GetMyContextFromRoot(root)
    field = {name: i for i, name in enumerate(SAMPLE_FIELDS)}
    pressed = 0
    for t in np.arange(2.5, 4.5, 0.1):
        simulator.AdvanceTo(t)
        sample = element.get_sample_output_port().Eval(context)
        contact = element.contact(context)  # live, from the inputs and state
        np.testing.assert_array_equal(
            sample[[field["x_m"], field["y_m"], field["z_m"]]],
            element.get_tip_position_output_port().Eval(context),
        )
        np.testing.assert_array_equal(
            sample[[field["vx_m_per_s"], field["vy_m_per_s"], field["vz_m_per_s"]]],
            element.get_tip_velocity_output_port().Eval(context),
        )
        np.testing.assert_array_equal(
            sample[[field["force_x_N"], field["force_y_N"], field["force_z_N"]]],
            contact.force_W,
        )
        assert sample[field["penetration_m"]] == contact.penetration_m
        assert sample[field["surface_z_m"]] == contact.surface_z_m
        # The plant's next step reads the stored sample (its tick is now).
        forces = element.get_spatial_forces_output_port().Eval(context)
        np.testing.assert_array_equal(forces[0].F_Bq_W.translational(), contact.force_W)
        pressed += contact.force_N > 1.0
    assert pressed >= 5  # the comparison covered the tip in the tissue


def test_plant_state_input_gives_the_list_ports_numbers():
    """Built with the plant, the element reads its state vector: every output
    is bit-identical to the element fed the plant's pose and velocity lists."""
    from tests.systems.test_body_reader import (
        contexts_fed_both_ways,
        free_and_lifted_plant,
    )
    from vic_drake.tissue import RelaxationParams

    plant, plant_context = free_and_lifted_plant()
    kw = dict(
        indenter_body_index=BodyIndex(1), p_BT=np.array([0.001, -0.002, 0.07]),
        phantom_body_index=BodyIndex(2), friction_coefficient=0.3, along_normal=True,
        relaxation=RelaxationParams(fractions=(0.1, 0.2), time_constants_s=(0.05, 1.0)),
        update_period_s=0.002,
    )  # fmt: skip
    lists = TissueForceElement(_plane_phantom(), **kw)
    state = TissueForceElement(_plane_phantom(), plant=plant, **kw)
    c_lists, c_state = contexts_fed_both_ways(plant, plant_context, lists, state)
    assert state.get_penetration_output_port().Eval(c_state)[0] > 0  # In contact.
    for _ in range(3):  # Ticks move the relaxation branches.
        for port in ("tissue.force_W", "tissue.penetration", "tissue.surface_z",
                     "probe.position", "probe.velocity", "tissue.sample"):  # fmt: skip
            np.testing.assert_array_equal(
                state.GetOutputPort(port).Eval(c_state),
                lists.GetOutputPort(port).Eval(c_lists),
            )
        for a, b in zip(
            state.get_spatial_forces_output_port().Eval(c_state),
            lists.get_spatial_forces_output_port().Eval(c_lists),
        ):
            np.testing.assert_array_equal(a.F_Bq_W.get_coeffs(), b.F_Bq_W.get_coeffs())
            np.testing.assert_array_equal(a.p_BoBq_B, b.p_BoBq_B)
        for system, context in ((state, c_state), (lists, c_lists)):
            update = system.EvalUniquePeriodicDiscreteUpdate(context)
            context.get_mutable_discrete_state().SetFrom(update)
