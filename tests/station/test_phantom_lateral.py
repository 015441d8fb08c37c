"""A laterally moving phantom: joints only when asked, and the tissue follows it.

The tissue force element reads the phantom body's pose and velocity; these
tests check, against the pure contact law, that a phantom moved sideways
by its x, y joints presses the tip with the map shifted by that offset, and
that its velocity enters the penetration rate and the friction.
"""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from vic_drake.errors import VicDrakeError
from vic_drake.station import (
    MakeStation,
    StationParams,
    initial_q_for_tip,
    station_plant,
)
from vic_drake.tissue import SyntheticChestPhantom
from vic_drake.tissue.tip_contact import tip_contact

#: A nearly level point of the synthetic chest on soft tissue (as in
#: test_builder.py); the probe presses 6 mm into it.
XY = (-0.045, -0.40)
DEPTH_M = 0.006
#: Plain Hunt-Crossley (no relaxation: a static force), no sensor noise.
PARAMS = dict(sensor_noise_std_N=[0.0, 0.0, 0.0], tissue_law="hc")


@pytest.fixture(scope="module")
def phantom():
    return SyntheticChestPhantom()


def _q(phantom, params):
    s = float(phantom.surface_z(*XY))
    return initial_q_for_tip([*XY, s - DEPTH_M], params)


def _law(phantom, params, p_WT, v_WT, p_WPh, v_WPh):
    """The pure contact law with the element's lookup and settings."""
    lookup = phantom.point_lookup(resolution_m=params.tissue_lookup_resolution_m)
    return tip_contact(
        lookup,
        p_WT,
        v_WT,
        p_WPh,
        v_WPh,
        friction_coefficient=params.tissue_friction_coefficient,
        slip_speed_m_per_s=params.tissue_slip_speed_m_per_s,
        along_normal=params.tissue_force_along_normal,
    )


def test_lateral_joints_and_ports_only_when_asked(phantom):
    params = StationParams()
    plain = MakeStation(params, phantom=phantom)
    assert station_plant(plain).num_positions() == 7
    assert not plain.HasInputPort("phantom.lateral")
    assert not plain.HasOutputPort("phantom.lateral_offset")
    lateral = MakeStation(params, phantom=phantom, phantom_lateral=True)
    plant = station_plant(lateral)
    assert plant.num_positions() == 9
    assert lateral.GetInputPort("phantom.lift").size() == 1
    assert lateral.GetInputPort("phantom.lateral").size() == 2
    assert lateral.GetOutputPort("phantom.z_offset").size() == 1
    assert lateral.GetOutputPort("phantom.lateral_offset").size() == 2
    with pytest.raises(VicDrakeError, match="phantom_lateral"):
        MakeStation(params, phantom=phantom, phantom_lateral="yes")


def test_shifted_phantom_presses_with_the_map_at_the_tip_minus_the_shift(phantom):
    params = StationParams(**PARAMS)
    q = _q(phantom, params)
    station = MakeStation(params, phantom=phantom, initial_q=q, phantom_lateral=True)
    context = station.CreateDefaultContext()
    d = np.array([0.005, -0.004])
    station.GetInputPort("ur3e.position_command").FixValue(context, q)
    station.GetInputPort("phantom.lift").FixValue(context, [0.002])
    station.GetInputPort("phantom.lateral").FixValue(context, d)
    Simulator(station, context).AdvanceTo(0.3)
    # The joints hold the commanded offsets (the probe's 5 N sinks the lift
    # by F / kp ~ 3 um; the lateral forces move x, y by < 1 um).
    offset = station.GetOutputPort("phantom.lateral_offset").Eval(context)
    np.testing.assert_allclose(offset, d, atol=1e-6)
    lift = station.GetOutputPort("phantom.z_offset").Eval(context)[0]
    assert lift == pytest.approx(0.002, abs=5e-6)
    plant = station_plant(station)
    p_WPh = (
        plant.GetBodyByName("phantom")
        .EvalPoseInWorld(plant.GetMyContextFromRoot(context))
        .translation()
    )
    np.testing.assert_allclose(p_WPh, [*offset, lift], atol=1e-12)
    # The force: the pure law with the map shifted by the commanded d
    # (sampled at the tip minus d), not the unshifted one.
    p_WT = station.GetOutputPort("probe.position").Eval(context)
    v_WT = station.GetOutputPort("probe.velocity").Eval(context)
    f = station.GetOutputPort("tissue.force_W").Eval(context)
    shifted = _law(phantom, params, p_WT, v_WT, [*d, lift], np.zeros(3))
    unshifted = _law(phantom, params, p_WT, v_WT, [0.0, 0.0, lift], np.zeros(3))
    np.testing.assert_allclose(f, shifted.force_W, atol=2e-3)
    assert np.max(np.abs(unshifted.force_W - shifted.force_W)) > 0.1
    pen = station.GetOutputPort("tissue.penetration").Eval(context)[0]
    surface = phantom.surface_z(p_WT[0] - d[0], p_WT[1] - d[1]) + lift
    assert pen == pytest.approx(surface - p_WT[2], abs=2e-6)


def test_phantom_velocity_enters_the_penetration_rate_and_friction(phantom):
    # The phantom slides along +x at 1 cm/s under the held probe: relative
    # to the tissue the tip moves along -x, so the friction pushes the tip
    # along +x, and the penetration rate is -dz/dx * v.
    params = StationParams(**PARAMS)
    q = _q(phantom, params)
    v = 0.01
    builder = DiagramBuilder()
    station = builder.AddSystem(
        MakeStation(params, phantom=phantom, initial_q=q, phantom_lateral=True)
    )
    ramp = PiecewisePolynomial.FirstOrderHold(
        [0.0, 0.2, 0.5], np.array([[0.0, 0.0, 0.3 * v], [0.0, 0.0, 0.0]])
    )
    source = builder.AddSystem(TrajectorySource(ramp))
    builder.Connect(source.get_output_port(), station.GetInputPort("phantom.lateral"))
    for name, value in (("ur3e.position_command", q), ("phantom.lift", [0.0])):
        const = builder.AddSystem(ConstantVectorSource(value))
        builder.Connect(const.get_output_port(), station.GetInputPort(name))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    Simulator(diagram, context).AdvanceTo(0.4)
    sc = station.GetMyContextFromRoot(context)
    p_WT = station.GetOutputPort("probe.position").Eval(sc)
    v_WT = station.GetOutputPort("probe.velocity").Eval(sc)
    lift = station.GetOutputPort("phantom.z_offset").Eval(sc)[0]
    # The servo follows its command one command period (2 ms) late.
    p_cmd = [*ramp.value(0.4 - params.command_period_s).ravel(), lift]
    np.testing.assert_allclose(
        station.GetOutputPort("phantom.lateral_offset").Eval(sc),
        p_cmd[:2],
        atol=1e-6,
    )
    moving = _law(phantom, params, p_WT, v_WT, p_cmd, [v, 0.0, 0.0])
    still = _law(phantom, params, p_WT, v_WT, p_cmd, np.zeros(3))
    f = station.GetOutputPort("tissue.force_W").Eval(sc)
    tissue = station.GetSubsystemByName("tissue_force")
    rate = tissue.contact(tissue.GetMyContextFromRoot(context)).penetration_rate_m_per_s
    # Measured: 1.2 mN (z) and 0.6 mN (x) from the law with the commanded
    # motion; ignoring the phantom's velocity would be off by 1.2 N in x.
    np.testing.assert_allclose(f, moving.force_W, atol=5e-3)
    assert moving.friction_x_N > 0.8 * params.tissue_friction_coefficient * f[2]
    assert f[0] - still.force_W[0] > 1.0
    assert rate == pytest.approx(moving.penetration_rate_m_per_s, abs=1e-5)
    assert abs(rate - still.penetration_rate_m_per_s) > 2e-4
