"""Bodies' poses and velocities from a plant's state vector (PlantBodyReader)."""

import numpy as np
import pytest
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, PrismaticJoint, SpatialInertia

from vic_drake.errors import VicDrakeError
from vic_drake.systems.body_reader import PlantBodyReader


def free_and_lifted_plant():
    """A plant with a free body ("indenter", index 1) and a body on a z
    prismatic joint ("phantom", index 2), and a state [q; v] with the free
    body tilted about x by about pi (tool down), both bodies moving."""
    plant = MultibodyPlant(0.002)
    inertia = SpatialInertia.SolidSphereWithMass(0.1, 0.01)
    indenter = plant.AddRigidBody("indenter", inertia)
    phantom = plant.AddRigidBody("phantom", inertia)
    plant.AddJoint(
        PrismaticJoint("lift", plant.world_frame(), phantom.body_frame(), [0, 0, 1])
    )
    plant.Finalize()
    assert (int(indenter.index()), int(phantom.index())) == (1, 2)
    context = plant.CreateDefaultContext()
    quaternion = np.array([0.01, 1.0, 0.02, -0.03])  # w, x, y, z
    q_indenter = [*(quaternion / np.linalg.norm(quaternion)), 0.011, 0.019, 0.161]
    plant.SetPositions(context, plant.GetModelInstanceByName("DefaultModelInstance"),
                       [*q_indenter, 0.003])  # fmt: skip
    v = [0.2, -0.1, 0.3, 0.01, -0.02, -0.03, 0.015]  # w, v of the indenter; lift rate
    plant.SetVelocities(context, v)
    return plant, context


def contexts_fed_both_ways(plant, plant_context, lists, state):
    """Contexts of a system built without (``lists``) and with (``state``)
    ``plant=``, their body inputs fixed from ``plant_context``: the list ports
    it has, or the plant's state. First checks that each refuses the other's
    port."""
    with pytest.raises(VicDrakeError, match="no 'body_poses' input port"):
        state.get_body_poses_input_port()
    with pytest.raises(VicDrakeError, match="no 'plant_state' input port"):
        lists.get_plant_state_input_port()
    c_lists, c_state = lists.CreateDefaultContext(), state.CreateDefaultContext()
    lists.get_body_poses_input_port().FixValue(
        c_lists, plant.get_body_poses_output_port().Eval(plant_context)
    )
    if lists.HasInputPort("body_spatial_velocities"):
        lists.GetInputPort("body_spatial_velocities").FixValue(
            c_lists, plant.get_body_spatial_velocities_output_port().Eval(plant_context)
        )
    state.get_plant_state_input_port().FixValue(
        c_state, plant.get_state_output_port().Eval(plant_context)
    )
    return c_lists, c_state


def test_reads_the_same_poses_and_velocities_as_the_plants_list_ports():
    plant, context = free_and_lifted_plant()
    poses = plant.get_body_poses_output_port().Eval(context)
    velocities = plant.get_body_spatial_velocities_output_port().Eval(context)
    x = plant.get_state_output_port().Eval(context)
    reader = PlantBodyReader(plant, (BodyIndex(2), BodyIndex(1)))
    for _ in range(2):  # The scratch context keeps nothing between calls.
        for i, (X, V) in zip((2, 1), reader(x)):
            np.testing.assert_array_equal(X.GetAsMatrix34(), poses[i].GetAsMatrix34())
            np.testing.assert_array_equal(V.get_coeffs(), velocities[i].get_coeffs())
        (X,) = PlantBodyReader(plant, (BodyIndex(1),), velocities=False)(x)
        np.testing.assert_array_equal(X.GetAsMatrix34(), poses[1].GetAsMatrix34())
        # Another state in between.
        reader(plant.GetPositionsAndVelocities(plant.CreateDefaultContext()))


def test_bad_plants_and_bodies_are_named():
    plant, _ = free_and_lifted_plant()
    with pytest.raises(VicDrakeError, match="body index 3 is not a body"):
        PlantBodyReader(plant, (BodyIndex(3),))
    with pytest.raises(VicDrakeError, match="finalized"):
        PlantBodyReader(MultibodyPlant(0.002), (BodyIndex(0),))
    with pytest.raises(VicDrakeError, match="MultibodyPlant, got str"):
        PlantBodyReader("plant", (BodyIndex(0),))
