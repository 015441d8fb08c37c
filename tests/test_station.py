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
    "ur3e.state", "ft_sensor.force_W", "ft_sensor.wrench_S", "probe.position",
    "probe.velocity", "tissue.force_W", "tissue.penetration", "tissue.surface_z",
    "phantom.z_offset",
)
SIZES = {"ur3e.position_command": 6, "phantom.lift": 1, "ur3e.state": 12,
         "ft_sensor.force_W": 3, "ft_sensor.wrench_S": 6, "probe.position": 3,
         "probe.velocity": 3, "tissue.force_W": 3, "tissue.penetration": 1,
         "tissue.surface_z": 1, "phantom.z_offset": 1}

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
    [("time_step_s", 0.0), ("sensor_lag_samples", -2), ("joint_kp_Nm_per_rad", (1.0,) * 5),
     ("contact_approximation", "tamsi"), ("sensor_noise_std_N", (0, 0, -1))],
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
    # The position servo yields under the load by well under a millimetre.
    assert 0.009 < pen < 0.0101
    assert f_hc[2] > 5.0
    # Tared sensor = minus the tissue force (sensor convention), and nothing
    # else pushes the tool: Drake contact of the indenter is filtered out.
    np.testing.assert_allclose(f_ft, -f_hc, atol=1e-3)
    contacts = station.GetOutputPort("plant.contact_results").Eval(context)
    assert contacts.num_point_pair_contacts() == 0
    assert contacts.num_hydroelastic_contacts() == 0


def test_sensor_lags_the_tissue_force_by_the_set_samples(phantom):
    station, context, _ = _pressing_station(phantom, 0.005, sensor_noise_std_N=(0.0, 0.0, 0.0))
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
    assert station.GetOutputPort("phantom.z_offset").Eval(context)[0] == pytest.approx(0.003, abs=2e-4)
    lags = range(0, 50)
    err = [np.sum((f_ft[k:] - f_hc[: len(f_hc) - k]) ** 2) for k in lags]
    assert abs(int(np.argmin(err)) - 28) <= 1
