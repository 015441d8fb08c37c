"""The BOTA SensONE force/torque sensor: weld reaction, tare, noise, bias, lag.

The sensor is a weld joint between its mounting-side body (on the flange)
and its wrench-side body (carrying the indenter). Drake's reaction force of
that weld is exactly what a strain-gauge sensor measures: the spatial force
the mounting side exerts on everything beyond it (wrench side, indenter and
whatever touches the indenter), at the wrench frame S, expressed in S.

Reading pipeline (every ``period_s``, 500 Hz on the rig):

1. reaction ``F_S = [tau; f]`` of the weld, in S;
2. tare: subtract the static load of the distal mass in the current
   orientation (its weight held up by the sensor), so the reading is zero
   in free air at rest in any orientation;
3. add zero-mean Gaussian noise (standard deviations per axis);
4. delay by ``lag_samples`` periods (0 by default; the real logs pair
   each pose with the force 28 samples later, see
   :class:`vic_drake.station.StationParams`), then add a constant bias;
5. express the reading's force in W with the sensor's orientation at the
   sampling instant.

The reading is discrete state published with ``DeclareStateOutputPort``:
every consumer in a tick (controller, FDCC, loggers) reads the stored
sample, nothing is recomputed when the plant moves between samples.

Sign convention: the reading is the force the sensor applies to the tool
side. When the probe presses down into the body the tissue pushes the tool
up and the sensor holds it down, so the z force expressed in the world frame
is negative -- the convention of the real logs' sensor columns.
Component order of wrenches is Drake's ``[tau_x, tau_y, tau_z, f_x, f_y, f_z]``
(N m, N).
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, JointIndex
from pydrake.systems.framework import LeafSystem

from vic_drake.errors import VicDrakeError
from vic_drake.paper import GRAVITY_M_PER_S2
from vic_drake.systems.body_reader import PlantBodyReader, port_or_error


def tared_sensor_wrench(
    F_S, R_WS, *, distal_mass_kg: float, p_SScm, gravity_W=(0.0, 0.0, -GRAVITY_M_PER_S2)
) -> np.ndarray:
    """Removes the distal mass's static load from a sensor wrench.

    Args:
        F_S: measured wrench ``[tau; f]`` at S's origin, expressed in S (6,).
        R_WS: orientation of S in W (3, 3).
        distal_mass_kg: mass beyond the sensor (wrench side + tool), kg.
        p_SScm: its centre of mass from S's origin, in S, m (3,).
        gravity_W: gravity in W, m/s^2.

    Returns:
        The tared wrench ``[tau; f]`` in S (6,): zero in static free air.
    """
    F_S = np.asarray(F_S, float)
    g_S = np.asarray(R_WS, float).T @ np.asarray(gravity_W, float)
    f_static = -distal_mass_kg * g_S  # the sensor holds the weight up
    p = np.asarray(p_SScm, float)
    tau_static = np.array(
        [  # p x f_static (np.cross is slow on 3-vectors)
            p[1] * f_static[2] - p[2] * f_static[1],
            p[2] * f_static[0] - p[0] * f_static[2],
            p[0] * f_static[1] - p[1] * f_static[0],
        ]
    )
    return F_S - np.concatenate([tau_static, f_static])


class ForceTorqueSensor(LeafSystem):
    """Samples, tares, corrupts and delays the weld reaction (module doc).

    Input ports:
        reaction_forces: ``list[SpatialForce]`` (the plant's reaction forces
            port, indexed by joint index).
        body_poses: ``list[RigidTransform]`` (the plant's body poses port);
            built with ``plant``, instead:
        plant_state: (n_q + n_v) the plant's state port [q; v], from which
            the sensor body's pose is computed in a private context of
            ``plant`` (the same numbers as the list port; the plant's default
            parameters).
        noise: (6,) standard-normal samples (e.g. a RandomSource); if left
            unconnected the reading is noise free.
    Output ports:
        wrench_S: (6,) reading ``[tau; f]`` in the sensor frame S (N m, N).
        force_W: (3,) the reading's force expressed in W with the orientation
            of S at the last sample, N (negative z = pressing down into the
            body). Zero before the first sample.
    State (discrete, updated every ``period_s``): with ``lag_samples > 0``
    the last ``lag_samples + 1`` tared samples; the reading (wrench_S,
    force_W) they give.
    """

    def __init__(
        self,
        *,
        weld_joint_index: JointIndex,
        child_body_index: BodyIndex,
        X_CS: RigidTransform,
        distal_mass_kg: float,
        p_SScm,
        period_s: float = 0.002,
        lag_samples: int = 0,
        noise_std=(0.0,) * 6,
        bias=(0.0,) * 6,
        gravity_W=(0.0, 0.0, -GRAVITY_M_PER_S2),
        plant: MultibodyPlant | None = None,
    ):
        """
        Args:
            weld_joint_index: the sensor weld (its reaction is the reading).
            child_body_index: the weld's child body C (the wrench side).
            X_CS: pose of the weld's child frame (= sensor frame S) in C.
            distal_mass_kg: mass beyond the weld, kg (for the tare).
            p_SScm: its centre of mass from S, in S, m.
            period_s: sampling period, s.
            lag_samples: delay in samples (>= 0).
            noise_std: per-component noise std of ``[tau; f]`` (N m, N).
            bias: constant offset added to ``[tau; f]`` after the delay.
            gravity_W: gravity in W, m/s^2.
            plant: the finalized MultibodyPlant of the joint and body: the
                sensor then reads the plant's state (input "plant_state")
                instead of the body poses list (see the class doc).
        """
        super().__init__()
        if not (np.isfinite(period_s) and period_s > 0):
            raise VicDrakeError(f"period_s must be > 0, got {period_s!r}")
        if int(lag_samples) != lag_samples or lag_samples < 0:
            raise VicDrakeError(
                f"lag_samples must be an integer >= 0, got {lag_samples!r}"
            )
        self._joint = int(weld_joint_index)
        self._child = int(child_body_index)
        self._R_CS = X_CS.rotation().matrix()
        self._distal_mass = float(distal_mass_kg)
        self._p_SScm = np.asarray(p_SScm, float).reshape(3)
        self._noise_std = np.broadcast_to(np.asarray(noise_std, float), (6,)).copy()
        self._bias = np.broadcast_to(np.asarray(bias, float), (6,)).copy()
        self._gravity_W = np.asarray(gravity_W, float).reshape(3)
        self._noisy = bool(np.any(self._noise_std > 0))
        # tared_sensor_wrench as a matrix on gravity in S (computed once):
        # static load [p x f; f] with f = -m g_S.
        px, py, pz = self._p_SScm
        skew = np.array([[0.0, -pz, py], [pz, 0.0, -px], [-py, px, 0.0]])
        self._static_per_g = -self._distal_mass * np.vstack([skew, np.eye(3)])
        self._identity_CS = bool(np.array_equal(self._R_CS, np.eye(3)))
        self._n = int(lag_samples) + 1
        self._reaction_port = self.DeclareAbstractInputPort(
            "reaction_forces", AbstractValue.Make([SpatialForce()])
        )
        self._poses_port = self._state_port = None
        if plant is None:
            self._poses_port = self.DeclareAbstractInputPort(
                "body_poses", AbstractValue.Make([RigidTransform()])
            )
        else:
            self._reader = PlantBodyReader(plant, (child_body_index,), velocities=False)
            self._state_port = self.DeclareVectorInputPort(
                "plant_state", self._reader.num_states
            )
        self._noise_port = self.DeclareVectorInputPort("noise", 6)
        # Without a lag the reading is the newest sample: no buffer.
        self._buffer = self.DeclareDiscreteState(6 * self._n) if self._n > 1 else None
        self._wrench = self.DeclareDiscreteState(self._bias.copy())
        self._force = self.DeclareDiscreteState(3)
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._update)
        self._wrench_port = self.DeclareStateOutputPort("wrench_S", self._wrench)
        self._force_port = self.DeclareStateOutputPort("force_W", self._force)

    def get_reaction_forces_input_port(self):
        return self._reaction_port

    def get_body_poses_input_port(self):
        return port_or_error(self._poses_port, "body_poses", "a plant")

    def get_plant_state_input_port(self):
        return port_or_error(self._state_port, "plant_state", "no plant")

    def get_noise_input_port(self):
        return self._noise_port

    def get_wrench_output_port(self):
        return self._wrench_port

    def get_force_output_port(self):
        return self._force_port

    def _R_WC(self, context) -> np.ndarray:
        """The orientation of the sensor body C in W, from the inputs."""
        if self._state_port is None:
            X_WC = self._poses_port.Eval(context)[self._child]
        else:
            (X_WC,) = self._reader(self._state_port.Eval(context))
        return X_WC.rotation().matrix()

    def _R_WS(self, context) -> np.ndarray:
        """The orientation of the sensor frame S in W, from the inputs."""
        R_WC = self._R_WC(context)
        return R_WC if self._identity_CS else R_WC @ self._R_CS

    def tared_wrench(self, context) -> np.ndarray:
        """The noise-free, undelayed tared wrench ``[tau; f]`` in S now."""
        F_CS_S = self._reaction_port.Eval(context)[self._joint].get_coeffs()
        return tared_sensor_wrench(
            F_CS_S,
            self._R_WS(context),
            distal_mass_kg=self._distal_mass,
            p_SScm=self._p_SScm,
            gravity_W=self._gravity_W,
        )

    def _noise(self, context):
        """The noise input's samples, or None when the port has no value."""
        try:  # Connected in a station: one crossing, no HasValue.
            return self._noise_port.Eval(context)
        except RuntimeError:
            if self._noise_port.HasValue(context):
                raise
            return None

    def _update(self, context, discrete_state):
        R_WS = self._R_WS(context)
        F_S = self._reaction_port.Eval(context)[self._joint].get_coeffs()
        # = tared_sensor_wrench(F_S, R_WS, ...), one product per tick.
        sample = F_S - self._static_per_g @ (R_WS.T @ self._gravity_W)
        if self._noisy:
            noise = self._noise(context)
            if noise is not None:
                sample = sample + self._noise_std * noise
        if self._buffer is None:
            reading = sample + self._bias
        else:
            old = context.get_discrete_state(self._buffer).get_value()
            buffer = np.concatenate([sample, old[: 6 * (self._n - 1)]])
            discrete_state.set_value(self._buffer, buffer)
            reading = buffer[6 * (self._n - 1) :] + self._bias
        discrete_state.set_value(self._wrench, reading)
        discrete_state.set_value(self._force, R_WS @ reading[3:])
