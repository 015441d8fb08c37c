"""The phantom-lift disturbance config and the source built from it."""

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder

from vic_drake.errors import VicDrakeError
from vic_drake.scenario import DisturbanceConfig, PhantomLift
from vic_drake.systems.trajectory import PhantomLiftSource, phantom_lift_m


def _eval_at(system, port, t):
    context = system.CreateDefaultContext()
    context.SetTime(t)
    return port.Eval(context)


def test_phantom_lift_profile_and_source():
    lift = PhantomLift(start_s=1.0, height_m=0.02, rise_s=1.0, hold_s=2.0, fall_s=0.5)
    config = DisturbanceConfig(lifts=[lift])
    z = phantom_lift_m([0.0, 1.5, 2.0, 3.9, 4.25, 5.0], config)
    np.testing.assert_allclose(z, [0.0, 0.01, 0.02, 0.02, 0.01, 0.0], atol=1e-12)
    table = DisturbanceConfig(table=[[1.0, 0.0], [2.0, 0.01]])
    np.testing.assert_allclose(
        phantom_lift_m([0.0, 1.5, 9.0], table), [0.0, 0.005, 0.01]
    )
    source = PhantomLiftSource(config)
    builder = DiagramBuilder()
    builder.AddSystem(source)
    assert _eval_at(source, source.get_phantom_lift_output_port(), 1.5)[
        0
    ] == pytest.approx(0.01)


def test_lifts_and_table_are_exclusive():
    with pytest.raises(VicDrakeError, match="either lifts or table"):
        DisturbanceConfig(lifts=[PhantomLift()], table=[[0.0, 0.0]])
    assert DisturbanceConfig().is_nominal
