"""MakeStation: ports, static force check, sensor lag, safety contact."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from vic_drake.station import (
    MakeStation,
    StationParams,
    initial_q_for_tip,
    set_station_state,
    station_plant,
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

#: A nearly level point of the synthetic chest (surface slope < 0.04), on soft
#: tissue: the tests below press straight down and expect no sideways push.
XY = (-0.045, -0.40)


@pytest.fixture(scope="module")
def phantom():
    return SyntheticChestPhantom()


def pressing_station(phantom, depth_m, **kw):
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


def test_static_press_sensor_reads_the_hunt_crossley_force_once(phantom):
    # 6 mm into the synthetic chest at XY: about 5.5 N.
    station, context, _ = pressing_station(
        phantom, 0.006, sensor_lag_samples=0, sensor_noise_std_N=(0.0, 0.0, 0.0)
    )
    simulator = Simulator(station, context)
    simulator.AdvanceTo(0.3)
    pen = station.GetOutputPort("tissue.penetration").Eval(context)[0]
    f_hc = station.GetOutputPort("tissue.force_W").Eval(context)
    f_ft = station.GetOutputPort("ft_sensor.force_W").Eval(context)
    # The servo (integral action) holds the pose; the phantom sinks a few um.
    assert 0.0059 < pen < 0.00601
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
    station, context, _ = pressing_station(
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

    set_station_state(station, context, q)
    plant = station_plant(station)
    # The plant's output ports are sampled: take one step to fill them.
    Simulator(station, context).AdvanceTo(params.plant.time_step)
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
