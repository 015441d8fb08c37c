"""The UR3e model and tool: the probe frame and FDCC's internal model."""

import numpy as np
import pytest
from pydrake.math import RigidTransform

from vic_drake.control.fdcc import FdccModel, FdccParams
from vic_drake.models.ur3e import (
    UR3E_JOINTS,
    MakeFdccModel,
    MakeUr3ePlant,
    probe_down_rotation,
)
from vic_drake.station import StationParams


def test_probe_frame_sits_at_the_tool_tip_below_the_flange():
    params = StationParams()
    plant, handles = MakeUr3ePlant(params)
    context = plant.CreateDefaultContext()
    X_3P = handles.probe_frame.CalcPose(
        context, plant.GetFrameByName("wrist_3_link", handles.ur3e)
    )
    np.testing.assert_allclose(
        X_3P.GetAsMatrix4(),
        (params.X_W3M @ RigidTransform(params.p_MP)).GetAsMatrix4(),
        atol=1e-12,
    )
    assert plant.num_positions() == len(UR3E_JOINTS)
    np.testing.assert_allclose(
        probe_down_rotation().matrix(), np.diag([1.0, -1.0, -1.0]), atol=1e-15
    )


def test_fdcc_model_has_light_links_and_the_probe_pose_of_the_tool():
    params, station = FdccParams(), StationParams()
    model = MakeFdccModel(params, station)
    assert isinstance(model, FdccModel)
    plant, handles = MakeUr3ePlant(station)
    context = plant.CreateDefaultContext()
    q = np.array([-2.1, -1.4, 1.7, -1.87, -1.57, -2.1])
    plant.SetPositions(context, q)
    np.testing.assert_allclose(
        model.pose(q).GetAsMatrix4(),
        handles.probe_frame.CalcPoseInWorld(context).GetAsMatrix4(),
        atol=1e-12,
    )
    # Six light links (0.1 kg each) and the unit end-effector mass.
    _, H, _ = model.dynamics(q)
    assert np.all(np.linalg.eigvalsh(H) > 0)
    mass = sum(
        model.plant.get_joint(i).child_body().get_mass(model._context)
        for i in model.plant.GetJointIndices()
        if model.plant.get_joint(i).num_velocities() > 0
    )
    assert mass == pytest.approx(len(UR3E_JOINTS) * params.link_mass_kg)
