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
