"""The station's tissue law field: relaxing Hunt-Crossley or plain HC."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from vic_drake.errors import VicDrakeError
from vic_drake.station import MakeStation, StationParams, initial_q_for_tip
from vic_drake.tissue import (
    DEFAULT_RELAXATION,
    SyntheticChestPhantom,
)

XY = (-0.045, -0.40)  # A nearly level, soft point (as in test_builder).


def _press(phantom, law, depth_m=0.006, t_s=0.3):
    params = StationParams(tissue_law=law, sensor_noise_std_N=[0.0, 0.0, 0.0])
    q = initial_q_for_tip([*XY, float(phantom.surface_z(*XY)) - depth_m], params)
    station = MakeStation(params, phantom=phantom, initial_q=q)
    context = station.CreateDefaultContext()
    station.GetInputPort("ur3e.position_command").FixValue(context, q)
    station.GetInputPort("phantom.lift").FixValue(context, [0.0])
    Simulator(station, context).AdvanceTo(t_s)
    tissue = station.GetSubsystemByName("tissue_force")
    return station, context, tissue, tissue.GetMyContextFromRoot(context)


def test_default_law_relaxes_and_hc_has_no_state():
    assert StationParams().tissue_law == "relaxing"
    phantom = SyntheticChestPhantom()
    station, context, tissue, _ = _press(phantom, "relaxing")
    tissue_context = tissue.GetMyMutableContextFromRoot(context)
    index = tissue.get_relaxation_state_index()
    s = tissue_context.get_discrete_state(index).get_value().copy()
    assert s.shape == (DEFAULT_RELAXATION.n_branches,) and np.all(s > 0.0)
    force = station.GetOutputPort("tissue.force_W").Eval(context)[2]
    sample = phantom.sample(np.array([XY[0]]), np.array([XY[1]]))
    relaxed = float(sample.kappa[0]) * float(np.dot(DEFAULT_RELAXATION.fractions, s))
    # The same pose with the branch state emptied: the force is higher by
    # the relaxed part kappa g s (to the element's 0.5 mm kappa lookup).
    tissue_context.SetDiscreteState(index, np.zeros_like(s))
    fresh = station.GetOutputPort("tissue.force_W").Eval(context)[2]
    assert relaxed > 0.0
    assert fresh - force == pytest.approx(relaxed, rel=1e-4)
    _, _, hc_tissue, hc_context = _press(phantom, "hc", t_s=0.01)
    assert hc_tissue.get_relaxation_state_index() is None
    # Only the stored sample and its tick.
    assert hc_context.num_discrete_state_groups() == 2


def test_unknown_tissue_law_is_named():
    with pytest.raises(VicDrakeError, match="tissue_law"):
        StationParams(tissue_law="maxwell")


def test_given_relaxation_branches_reach_the_tissue_element():
    """Two given branches: two states, and the force drops by kappa sum g_i s_i."""
    phantom = SyntheticChestPhantom()
    params = StationParams(
        sensor_noise_std_N=[0.0, 0.0, 0.0],
        tissue_relaxation_fractions=[0.05, 0.1],
        tissue_relaxation_time_constants_s=[0.1, 30.0],
    )
    q = initial_q_for_tip([*XY, float(phantom.surface_z(*XY)) - 0.006], params)
    station = MakeStation(params, phantom=phantom, initial_q=q)
    context = station.CreateDefaultContext()
    station.GetInputPort("ur3e.position_command").FixValue(context, q)
    station.GetInputPort("phantom.lift").FixValue(context, [0.0])
    Simulator(station, context).AdvanceTo(0.3)
    tissue = station.GetSubsystemByName("tissue_force")
    tissue_context = tissue.GetMyMutableContextFromRoot(context)
    index = tissue.get_relaxation_state_index()
    s = tissue_context.get_discrete_state(index).get_value().copy()
    assert s.shape == (2,)
    # After 0.3 s the fast branch (0.1 s) has nearly caught up, the slow one
    # (30 s) has not.
    assert s[0] > 10.0 * s[1] > 0.0
    force = station.GetOutputPort("tissue.force_W").Eval(context)[2]
    tissue_context.SetDiscreteState(index, np.zeros_like(s))
    fresh = station.GetOutputPort("tissue.force_W").Eval(context)[2]
    sample = phantom.sample(np.array([XY[0]]), np.array([XY[1]]))
    relaxed = float(sample.kappa[0]) * float(np.dot([0.05, 0.1], s))
    assert fresh - force == pytest.approx(relaxed, rel=1e-4)


def test_default_branches_are_the_default_relaxation():
    assert StationParams().relaxation is DEFAULT_RELAXATION
    assert StationParams(tissue_law="hc").relaxation is None
    given = StationParams(
        tissue_relaxation_fractions=[0.03, 0.09],
        tissue_relaxation_time_constants_s=[1.7, 65.0],
    ).relaxation
    assert given.fractions == (0.03, 0.09)
    assert given.time_constants_s == (1.7, 65.0)


@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(tissue_relaxation_fractions=[0.1]), "one value per branch"),
        (
            dict(
                tissue_law="hc",
                tissue_relaxation_fractions=[0.1],
                tissue_relaxation_time_constants_s=[1.0],
            ),
            "need tissue_law 'relaxing'",
        ),
        (
            dict(
                tissue_relaxation_fractions=[0.6, 0.5],
                tissue_relaxation_time_constants_s=[1.0, 2.0],
            ),
            "tissue_relaxation_fractions must be finite, >= 0 and sum to < 1",
        ),
        (
            dict(
                tissue_relaxation_fractions=[0.1],
                tissue_relaxation_time_constants_s=[0.0],
            ),
            "tissue_relaxation_time_constants_s must be finite and > 0",
        ),
        (
            dict(
                tissue_relaxation_fractions=["a"],
                tissue_relaxation_time_constants_s=[1.0],
            ),
            "tissue_relaxation_fractions must be a list of numbers",
        ),
    ],
)
def test_bad_relaxation_branches_are_named(kw, words):
    with pytest.raises(VicDrakeError, match=words):
        StationParams(**kw)


def test_relaxation_branches_load_from_yaml():
    from pydrake.common.yaml import yaml_load_typed

    params = yaml_load_typed(
        schema=StationParams,
        data="tissue_relaxation_fractions: [0.03, 0.09]\n"
        "tissue_relaxation_time_constants_s: [1.7, 65.0]\n",
    )
    params.validate()
    assert params.relaxation.time_constants_s == (1.7, 65.0)
    bad = yaml_load_typed(
        schema=StationParams,
        data="tissue_law: hc\ntissue_relaxation_fractions: [0.03]\n"
        "tissue_relaxation_time_constants_s: [1.7]\n",
    )
    with pytest.raises(VicDrakeError, match="tissue_relaxation_fractions"):
        bad.validate()
