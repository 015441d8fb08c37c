"""Inverse and forward kinematics of the probe tip on the UR3e with its tool."""

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import Solve

from vic_drake.errors import VicDrakeError
from vic_drake.models.ur3e import MakeUr3ePlant, probe_down_rotation
from vic_drake.station.params import StationParams

#: A configuration with the probe pointing down over the phantom (IK seed).
DEFAULT_Q_SEED = (-2.1, -1.4, 1.7, -1.87, -1.57, -2.1)
#: Further seeds tried when no q_seed is given and DEFAULT_Q_SEED fails
#: (arm stretched out, arm pulled in, elbow-up home).
FALLBACK_Q_SEEDS = (
    (-2.1, -0.9, 0.9, -1.57, -1.57, -2.1),
    (-2.1, -1.9, 2.4, -2.07, -1.57, -2.1),
    (-1.57, -1.57, 1.57, -1.57, -1.57, 0.0),
)


def solve_tip_ik(
    p_WP,
    *,
    q_seed=None,
    params: StationParams | None = None,
    R_WP: RotationMatrix | None = None,
    position_tolerance_m: float = 1e-6,
    angle_tolerance_rad: float = 1e-6,
) -> np.ndarray:
    """Joint angles placing the probe tip at p_WP with the tool pointing down.

    Solves Drake's InverseKinematics (nearest to ``q_seed`` in the joint
    norm) for the probe frame at ``p_WP`` with orientation ``R_WP`` (default
    :func:`probe_down_rotation`).

    Args:
        p_WP: tip position in W (the rig's base_link), m (3,).
        q_seed: initial guess and cost centre, rad (6,); default
            DEFAULT_Q_SEED, then FALLBACK_Q_SEEDS if that fails.
        params: station geometry (tool length); default StationParams().
        R_WP: tip orientation; default pointing straight down.
        position_tolerance_m, angle_tolerance_rad: constraint tolerances.

    Returns:
        q (6,), rad, in :data:`UR3E_JOINTS` order.

    Raises:
        VicDrakeError: p_WP is not finite or the pose is unreachable.
    """
    p_WP = np.asarray(p_WP, float)
    if p_WP.shape != (3,) or not np.all(np.isfinite(p_WP)):
        raise VicDrakeError(f"p_WP must be 3 finite numbers (m), got {p_WP!r}")
    seeds = [DEFAULT_Q_SEED, *FALLBACK_Q_SEEDS] if q_seed is None else [q_seed]
    seeds = [np.asarray(seed, float) for seed in seeds]
    if seeds[0].shape != (6,) or not np.all(np.isfinite(seeds[0])):
        raise VicDrakeError(
            f"q_seed must be 6 finite joint angles (rad), got {q_seed!r}"
        )
    plant, handles = MakeUr3ePlant(params or StationParams())
    R_WP = R_WP or probe_down_rotation()
    ik = InverseKinematics(plant)
    tol = np.full(3, position_tolerance_m)
    ik.AddPositionConstraint(
        handles.probe_frame, np.zeros(3), plant.world_frame(), p_WP - tol, p_WP + tol
    )
    ik.AddOrientationConstraint(
        plant.world_frame(),
        R_WP,
        handles.probe_frame,
        RotationMatrix(),
        angle_tolerance_rad,
    )
    prog = ik.get_mutable_prog()
    q = ik.q()
    cost = prog.AddQuadraticErrorCost(np.eye(6), seeds[0], q)
    for seed in seeds:
        cost.evaluator().UpdateCoefficients(2 * np.eye(6), -2 * seed, seed @ seed)
        prog.SetInitialGuess(q, seed)
        result = Solve(prog)
        if result.is_success():
            return result.GetSolution(q)
    raise VicDrakeError(
        f"no joint configuration puts the probe tip at {p_WP.tolist()} m pointing down "
        f"(solver {result.get_solver_id().name()}, {len(seeds)} seed(s)); the UR3e "
        "reaches about 0.5 m from its shoulder"
    )


def initial_q_for_tip(p_WP, params: StationParams | None = None) -> np.ndarray:
    """Joint angles for a start tip position, probe pointing down (IK from the seed)."""
    return solve_tip_ik(p_WP, params=params)


def probe_pose(q, params: StationParams | None = None) -> RigidTransform:
    """Forward kinematics: X_WP of the probe tip for joint angles q (6,)."""
    plant, handles = MakeUr3ePlant(params or StationParams())
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, handles.ur3e, np.asarray(q, float))
    return handles.probe_frame.CalcPoseInWorld(context)


__all__ = [
    "DEFAULT_Q_SEED",
    "FALLBACK_Q_SEEDS",
    "initial_q_for_tip",
    "probe_pose",
    "solve_tip_ik",
]
