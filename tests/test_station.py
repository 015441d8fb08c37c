"""The simulated rig: ports, frames, static force check, sensor lag."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from vic_drake.errors import VicDrakeError
from vic_drake.station import (
    MakeStation,
    StationParams,
    initial_q_for_tip,
    probe_down_rotation,
    probe_pose,
    solve_tip_ik,
)
from vic_drake.tissue import SyntheticChestPhantom

INPUTS = ("ur3e.position_command", "phantom.lift")
OUTPUTS = (
    "ur3e.state",
    "ft_sensor.force_W",
    "ft_sensor.wrench_S",
    "probe.position",
    "probe.velocity",
    "tissue.force_W",
    "tissue.penetration",
    "tissue.surface_z",
    "phantom.z_offset",
)
SIZES = {
    "ur3e.position_command": 6,
    "phantom.lift": 1,
    "ur3e.state": 12,
    "ft_sensor.force_W": 3,
    "ft_sensor.wrench_S": 6,
    "probe.position": 3,
    "probe.velocity": 3,
    "tissue.force_W": 3,
    "tissue.penetration": 1,
    "tissue.surface_z": 1,
    "phantom.z_offset": 1,
}

XY = (-0.06, -0.36)


@pytest.fixture(scope="module")
def phantom():
    return SyntheticChestPhantom()


def _pressing_station(phantom, depth_m, **kw):
    params = StationParams(**kw)
    s = float(phantom.surface_z(*XY))
    q = initial_q_for_tip([*XY, s - depth_m], params)
    station = MakeStation(params, phantom=phantom, initial_q=q)
    context = station.CreateDefaultContext()
    station.GetInputPort("ur3e.position_command").FixValue(context, q)
    station.GetInputPort("phantom.lift").FixValue(context, [0.0])
    return station, context, q


def test_station_builds_with_the_contract_ports(phantom):
    station = MakeStation(StationParams(), phantom=phantom)
    assert station.get_name() == "station"
    for name in INPUTS:
        assert station.GetInputPort(name).size() == SIZES[name]
    for name in OUTPUTS:
        assert station.GetOutputPort(name).size() == SIZES[name]


def test_world_is_the_rigs_base_link_and_ik_points_the_probe_down():
    p = np.array([-0.1, -0.36, 0.1])  # inside the measured map, above the surface
    q = solve_tip_ik(p)
    X_WP = probe_pose(q)
    np.testing.assert_allclose(X_WP.translation(), p, atol=1e-5)
    np.testing.assert_allclose(
        X_WP.rotation().matrix(), probe_down_rotation().matrix(), atol=1e-5
    )
    # z of the probe points down, as the real controller's target (x = 1, w = 0).
    np.testing.assert_allclose(X_WP.rotation().matrix()[:, 2], [0, 0, -1], atol=1e-5)


def test_unreachable_tip_is_a_clear_error():
    with pytest.raises(VicDrakeError, match="no joint configuration"):
        initial_q_for_tip([2.0, 0.0, 0.1])


@pytest.mark.parametrize(
    "field, value",
    [
        ("time_step_s", 0.0),
        ("sensor_lag_samples", -2),
        ("joint_kp_Nm_per_rad", (1.0,) * 5),
        ("contact_approximation", "tamsi"),
        ("sensor_noise_std_N", (0, 0, -1)),
    ],
)
def test_bad_params_name_the_field(field, value):
    with pytest.raises(VicDrakeError, match=field):
        StationParams(**{field: value})


def test_static_press_sensor_reads_the_hunt_crossley_force_once(phantom):
    station, context, _ = _pressing_station(
        phantom, 0.01, sensor_lag_samples=0, sensor_noise_std_N=(0.0, 0.0, 0.0)
    )
    simulator = Simulator(station, context)
    simulator.AdvanceTo(0.3)
    pen = station.GetOutputPort("tissue.penetration").Eval(context)[0]
    f_hc = station.GetOutputPort("tissue.force_W").Eval(context)
    f_ft = station.GetOutputPort("ft_sensor.force_W").Eval(context)
    # The servo (integral action) holds the pose; the phantom sinks ~4 um.
    assert 0.0099 < pen < 0.01001
    assert f_hc[2] > 5.0
    # Tared sensor = minus the tissue force (sensor convention), and nothing
    # else pushes the tool: Drake contact of the indenter is filtered out.
    # The lateral part (normal tilt and friction, ~0.1 N here) differs by a
    # few mN: the arm's servo sways under it, and the friction follows the
    # sway's tiny velocities.
    np.testing.assert_allclose(f_ft[2], -f_hc[2], atol=1e-3)
    np.testing.assert_allclose(f_ft[:2], -f_hc[:2], atol=5e-3)
    contacts = station.GetOutputPort("plant.contact_results").Eval(context)
    assert contacts.num_point_pair_contacts() == 0
    assert contacts.num_hydroelastic_contacts() == 0


def test_sensor_lags_the_tissue_force_by_the_set_samples(phantom):
    station, context, _ = _pressing_station(
        phantom, 0.005, sensor_lag_samples=28, sensor_noise_std_N=(0.0, 0.0, 0.0)
    )
    simulator = Simulator(station, context)
    simulator.AdvanceTo(0.2)
    # Lift the phantom by 3 mm; the true force rises at once, the reading 28
    # samples (56 ms) later.
    station.GetInputPort("phantom.lift").FixValue(context, [0.003])
    t, f_hc, f_ft = [], [], []
    while context.get_time() < 0.4:
        simulator.AdvanceTo(context.get_time() + 0.002)
        t.append(context.get_time())
        f_hc.append(station.GetOutputPort("tissue.force_W").Eval(context)[2])
        f_ft.append(-station.GetOutputPort("ft_sensor.force_W").Eval(context)[2])
    f_hc, f_ft = np.array(f_hc), np.array(f_ft)
    assert station.GetOutputPort("phantom.z_offset").Eval(context)[0] == pytest.approx(
        0.003, abs=2e-4
    )
    lags = range(0, 50)
    err = [np.sum((f_ft[k:] - f_hc[: len(f_hc) - k]) ** 2) for k in lags]
    assert abs(int(np.argmin(err)) - 28) <= 1


def test_phantom_volume_mesh_is_valid_and_follows_the_surface(phantom):
    from vic_drake.models.phantom_mesh import boundary_triangles, phantom_volume_mesh

    vertices, tets = phantom_volume_mesh(phantom, resolution_m=0.03, thickness_m=0.05)
    a, b, c, d = (vertices[tets[:, i]] for i in range(4))
    volumes = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6
    assert np.all(volumes > 0)
    x_min, x_max, y_min, y_max = phantom.bounds
    top = vertices[
        np.isclose(vertices[:, 2], phantom.surface_z(vertices[:, 0], vertices[:, 1]))
    ]
    assert len(top) >= ((x_max - x_min) / 0.03) * ((y_max - y_min) / 0.03)
    # The slab's volume is the integral of its height.
    footprint = (x_max - x_min) * (y_max - y_min)
    # (the grid mean of the height weights the edges like the interior: ~3 %)
    assert volumes.sum() == pytest.approx(
        footprint * (np.mean(top[:, 2]) - vertices[:, 2].min()), rel=0.05
    )
    # A closed boundary: every edge of the surface is shared by two faces.
    faces = boundary_triangles(vertices, tets)
    edges = np.sort(
        np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1
    )
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)


def test_links_meet_the_phantom_but_the_indenter_does_not(phantom):
    """Kinematically push the tool 9 cm into the phantom: the sensor housing
    (7 cm above the tip) meets the compliant mesh; the indenter never does."""
    params = StationParams()
    station = MakeStation(params, phantom=phantom)
    context = station.CreateDefaultContext()
    s = float(phantom.surface_z(*XY))
    q = initial_q_for_tip([*XY, s - 0.09], params)
    station.GetInputPort("ur3e.position_command").FixValue(context, q)
    station.GetInputPort("phantom.lift").FixValue(context, [0.0])
    from vic_drake.station import set_station_state, station_plant

    set_station_state(station, context, q)
    plant = station_plant(station)
    # The plant's output ports are sampled: take one step to fill them.
    Simulator(station, context).AdvanceTo(params.time_step_s)
    contacts = station.GetOutputPort("plant.contact_results").Eval(context)
    assert contacts.num_hydroelastic_contacts() >= 1
    inspector = station.GetSubsystemByName("scene_graph").model_inspector()
    touching = set()
    for i in range(contacts.num_hydroelastic_contacts()):
        surface = contacts.hydroelastic_contact_info(i).contact_surface()
        for gid in (surface.id_M(), surface.id_N()):
            touching.add(plant.GetBodyFromFrameId(inspector.GetFrameId(gid)).name())
    assert "phantom" in touching
    assert "indenter" not in touching
    assert touching & {"ft_sensor_wrench", "ft_sensor_mount"}


def test_servo_linear_system_steps_as_the_filter_and_integral():
    """One tick of the servo's LinearSystem against joint_filter_step and the
    integral written out (period 2 ms, tau 0.03 s, T_i 0.05 s)."""
    from pydrake.systems.primitives import LinearSystem

    from vic_drake.station import (
        joint_filter_step,
        joint_servo_rest_state,
        joint_servo_system_matrices,
    )

    T, tau, ti = 0.002, 0.03, 0.05
    servo = LinearSystem(*joint_servo_system_matrices(6, T, tau, ti), T)
    context = servo.CreateDefaultContext()
    rng = np.random.default_rng(0)
    q_f, v, integral = rng.normal(size=(3, 6))
    context.SetDiscreteState(np.concatenate([q_f, v, integral]))
    command, measured = rng.normal(size=(2, 6))
    servo.get_input_port().FixValue(context, np.concatenate([command, measured]))
    x = servo.EvalUniquePeriodicDiscreteUpdate(context).get_vector().CopyToVector()
    q_next, v_next = joint_filter_step(q_f, command, T, tau)
    i_next = integral + (T / ti) * (q_f - measured)
    np.testing.assert_allclose(x, np.concatenate([q_next, v_next, i_next]), atol=1e-12)
    context.SetDiscreteState(x)
    np.testing.assert_allclose(
        servo.get_output_port().Eval(context),
        np.concatenate([q_next + i_next, v_next]),
        atol=1e-12,
    )
    # No integral term with T_i = 0; at rest the output is (q, 0).
    A, B, _, _ = joint_servo_system_matrices(6, T, tau, 0.0)
    assert not A[12:, :12].any() and not B[12:].any()
    rest = joint_servo_rest_state(q_f)
    np.testing.assert_array_equal(rest, np.concatenate([q_f, np.zeros(12)]))
