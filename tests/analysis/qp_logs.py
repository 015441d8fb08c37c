"""Test helper: a 31-column log whose stiffness columns the QP recomputes.

:func:`with_qp_stiffness` re-runs the real controller's stiffness QP over a
log's own inputs at a chosen R, in closed loop (each tick's damping from the
stiffness it computed the tick before, as the controller did), and writes
its answers into the stiffness columns: a log as the controller would have
logged it at that R, with every other column as measured.
"""

import math

import numpy as np
import pandas as pd

from vic_drake.analysis.r_weight_id import logged_params
from vic_drake.control.stiffness_qp import (
    make_stiffness_qp_problem,
    solve_stiffness_qp_exact,
)

STIFFNESS_COLUMNS = (
    "stiffness_x_N_per_m",
    "stiffness_y_N_per_m",
    "stiffness_z_N_per_m",
)


def with_qp_stiffness(real: pd.DataFrame, r_weight: float) -> pd.DataFrame:
    """A copy of ``real`` with K_x, K_y, K_z from the QP at R = ``r_weight``."""
    params = logged_params(real, r_weight)
    qp, tank = params.qp, params.tank
    cols = [
        "t_s", "x_m", "y_m", "z_m", "x_d_m", "y_d_m", "z_d_m",
        "vx_m_per_s", "vy_m_per_s", "vz_m_per_s", "force_ref_z_N", "force_min_z_N",
        "tank_energy_J",
    ]  # fmt: skip
    data = real[cols].to_numpy(dtype=float).tolist()
    k = real[list(STIFFNESS_COLUMNS)].to_numpy(dtype=float, copy=True)
    k_min = tuple(qp.stiffness_min_N_per_m)
    for j in range(1, len(data)):
        prev, row = data[j - 1], data[j]
        t, x, y, z, xd, yd, zd, vx, vy, vz, f_ref, f_min, _ = row
        energy = prev[12]
        if energy < tank.min_energy_J:
            k[j] = k_min
            continue
        damping = tuple(2.0 * qp.damping_ratio * math.sqrt(v) for v in k[j - 1])
        problem = make_stiffness_qp_problem(
            (xd - x, yd - y, zd - z), (-vx, -vy, -vz), damping, (0.0, 0.0, f_ref),
            (*qp.force_min_N[:2], f_min), energy, t - prev[0], qp, tank,
        )  # fmt: skip
        k[j] = solve_stiffness_qp_exact(problem).stiffness
    out = real.copy()
    out[list(STIFFNESS_COLUMNS)] = np.asarray(k)
    out.attrs.update(real.attrs)
    return out
