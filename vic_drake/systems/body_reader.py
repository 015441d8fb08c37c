"""Bodies' world poses and velocities from a MultibodyPlant's state vector.

The plant's ``body_poses`` and ``body_spatial_velocities`` ports hand Python
a list of every body's pose or velocity; a system that needs one or two
bodies can instead read the plant's ``state`` vector port and ask a private
context of the same plant (:class:`PlantBodyReader`). Both routes run the
plant's own kinematics on the same q and v, so they give the same numbers.
"""

from __future__ import annotations

from pydrake.multibody.plant import MultibodyPlant

from vic_drake.errors import VicDrakeError


class PlantBodyReader:
    """Poses (and spatial velocities) in W of some bodies, for a plant state.

    Holds a scratch context of ``plant`` (its default parameters) whose
    state is overwritten by every call: no state is carried between calls,
    so the result depends on the given [q; v] only.
    """

    def __init__(self, plant: MultibodyPlant, body_indices, *, velocities: bool = True):
        """
        Args:
            plant: a finalized MultibodyPlant.
            body_indices: the bodies to read (BodyIndex).
            velocities: also evaluate the bodies' spatial velocities.
        """
        if not isinstance(plant, MultibodyPlant):
            raise VicDrakeError(
                f"plant must be a MultibodyPlant, got {type(plant).__name__}"
            )
        if not plant.is_finalized():
            raise VicDrakeError("plant must be finalized before reading its bodies")
        bodies = []
        for index in body_indices:
            if not 0 <= int(index) < plant.num_bodies():
                raise VicDrakeError(
                    f"body index {int(index)} is not a body of the plant "
                    f"(0 to {plant.num_bodies() - 1})"
                )
            bodies.append(plant.get_body(index))
        self.num_states = plant.num_multibody_states()
        self._context = plant.CreateDefaultContext()
        self._bodies = tuple(bodies)
        # The per-call functions, bound once.
        self._set_state = plant.SetPositionsAndVelocities
        self._pose = plant.EvalBodyPoseInWorld
        self._velocity = plant.EvalBodySpatialVelocityInWorld if velocities else None

    def __call__(self, x):
        """For state ``x`` ([q; v] of the whole plant): a tuple, per body, of
        (X_WB, V_WB) (or X_WB alone, without ``velocities``)."""
        context = self._context
        self._set_state(context, x)
        pose, velocity = self._pose, self._velocity
        if velocity is None:
            return tuple(pose(context, body) for body in self._bodies)
        return tuple((pose(context, b), velocity(context, b)) for b in self._bodies)


def port_or_error(port, name: str, other_mode: str):
    """``port``, or a VicDrakeError naming it if the system was built without it."""
    if port is None:
        raise VicDrakeError(
            f"this system has no {name!r} input port (built with {other_mode})"
        )
    return port


__all__ = ["PlantBodyReader", "port_or_error"]
