"""The FDCC layer's settings (:class:`FdccParams`), loadable from YAML.

:class:`FdccParams` is a mutable dataclass loadable by Drake's
``yaml_load_typed`` (which fills a default instance field by field), so it
validates in ``__post_init__`` and again in :meth:`FdccParams.validate`. (No
``from __future__ import annotations`` here: the YAML loader reads the field
types at run time.) The tick itself is :mod:`vic_drake.control.fdcc`.
"""

from dataclasses import dataclass, field

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix

from vic_drake.errors import VicDrakeError


def _check_vec(name, value, n, *, nonneg=False):
    a = np.asarray(value, float)
    if a.shape != (n,) or not np.all(np.isfinite(a)) or (nonneg and np.any(a < 0)):
        what = "non-negative " if nonneg else ""
        raise VicDrakeError(
            f"FdccParams.{name} must be {n} finite {what}numbers, got {value!r}"
        )


@dataclass
class FdccParams:
    """Settings of the FDCC layer (the real rig's, from the published source).

    Gains are ordered (trans x, trans y, trans z, rot x, rot y, rot z) in W.
    """

    period_s: float = 0.002  # Controller tick, s (500 Hz, the UR3e's rate).
    internal_period_s: float = 0.02  # Simulated time per internal step, s (FZI: 0.02).
    iterations: int = 1  # Internal steps per tick.
    error_scale: float = 0.5  # Scales the PD output (solver.error_scale).
    # Proportional gains of the Cartesian PD (x, y: 0.05; z: 0.3; rotation: 1.5).
    p_gains: list[float] = field(
        default_factory=lambda: [0.05, 0.05, 0.3, 1.5, 1.5, 1.5]
    )
    # Derivative gains, s (x, y: 0.005; z: 0.01; rotation: none).
    d_gains: list[float] = field(
        default_factory=lambda: [0.005, 0.005, 0.01, 0.0, 0.0, 0.0]
    )
    # Rotational stiffness about x, y, z of W, N m/rad.
    rotational_stiffness_Nm_per_rad: list[float] = field(
        default_factory=lambda: [50.0, 50.0, 50.0]
    )
    # Mass of each moving link of the model, kg (FZI default).
    link_mass_kg: float = 0.1
    link_inertia_kg_m2: float = 1e-6  # Their rotational inertia, kg m^2.
    end_effector_mass_kg: float = 1.0  # Model mass at the probe frame, kg.
    end_effector_inertia_kg_m2: float = 1.0  # Its rotational inertia, kg m^2.
    # Internal velocity factor per step (FZI: 10 % damping).
    velocity_decay: float = 0.9
    # Target orientation of the probe frame, quaternion (w, x, y, z): pointing down.
    target_orientation_wxyz: list[float] = field(
        default_factory=lambda: [0.0, 1.0, 0.0, 0.0]
    )
    # Pose in the Cartesian error: "measured" (of the synchronised measured
    # joints) or "command" (FZI: the model's pose after the previous tick's
    # step, i.e. of the last command). H and J use the measured joints in
    # both. Default "measured": with this simulation's trailing joint servo,
    # "command" makes a VS-VF replay ring; see docs/decisions.md, "FDCC pose
    # feedback".
    pose_feedback: str = "measured"

    def __post_init__(self):
        self.validate()

    def validate(self) -> "FdccParams":
        """Checks every field; raises VicDrakeError naming the bad one. Returns self."""
        for name in (
            "period_s",
            "internal_period_s",
            "error_scale",
            "link_mass_kg",
            "link_inertia_kg_m2",
            "end_effector_mass_kg",
            "end_effector_inertia_kg_m2",
        ):
            value = getattr(self, name)
            if not (
                isinstance(value, (int, float)) and np.isfinite(value) and value > 0
            ):
                raise VicDrakeError(
                    f"FdccParams.{name} must be a number > 0, got {value!r}"
                )
        it = self.iterations
        if isinstance(it, bool) or not isinstance(it, (int, np.integer)) or it < 1:
            raise VicDrakeError(
                f"FdccParams.iterations must be an integer >= 1, got {it!r}"
            )
        if not (0 < self.velocity_decay <= 1):
            raise VicDrakeError(
                f"FdccParams.velocity_decay must be in (0, 1], got {self.velocity_decay!r}"
            )
        if self.pose_feedback not in ("command", "measured"):
            raise VicDrakeError(
                "FdccParams.pose_feedback must be 'command' or 'measured', got "
                f"{self.pose_feedback!r}"
            )
        _check_vec("p_gains", self.p_gains, 6, nonneg=True)
        _check_vec("d_gains", self.d_gains, 6, nonneg=True)
        _check_vec(
            "rotational_stiffness_Nm_per_rad",
            self.rotational_stiffness_Nm_per_rad,
            3,
            nonneg=True,
        )
        _check_vec("target_orientation_wxyz", self.target_orientation_wxyz, 4)
        if not np.linalg.norm(self.target_orientation_wxyz) > 0.5:
            raise VicDrakeError(
                "FdccParams.target_orientation_wxyz must be a unit quaternion (w, x, y, z), "
                f"got {self.target_orientation_wxyz!r}"
            )
        return self

    @property
    def R_WP_target(self) -> RotationMatrix:
        """The target orientation of the probe frame."""
        w, x, y, z = np.asarray(self.target_orientation_wxyz, float)
        q = np.array([w, x, y, z]) / np.linalg.norm([w, x, y, z])
        return RotationMatrix(Quaternion(q))


__all__ = ["FdccParams"]
