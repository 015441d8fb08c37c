"""Replay of the real variable-impedance controller's logs through our QP and tank.

The real controller logged, every tick, the 31 columns of
:data:`vic_drake.realdata.CONTROLLER_COLUMNS`. For tick i >= 1 the inputs of
its QP are all in the log:

- e = x_d - x (columns x_d_m.. minus x_m..), e_dot = -x_dot (vx..vz),
- F_ref = (0, 0, force_ref_z_N), F_min = (F_min,x, F_min,y, force_min_z_N)
  (x, y from the parameters; the logged z values already carry the
  contact logic: F_ref = 0 and F_min,z = -F_max,z when the sensor's z force
  is >= -0.5 N),
- T before the tick = tank_energy_J of row i-1 (logged after each update),
- D = 2 zeta sqrt(K) with K the logged stiffness of row i-1,
- dt = t_i - t_{i-1} (the real controller used the clock, not 1/500 s).

We solve the same QP with the same tank rows and compare K_z to the logged
one, then step the tank from the logged T of row i-1 with our K and compare
with the logged T of row i. Ticks with T < T_min use K = K_min, as the real
controller did. R is not logged: it must be given (0.1 for test_tracking5,
1e-5 for test_nardi_matForce_lowR); the default of
:class:`StiffnessQpParams` is 0.1. The settings the controller logged every
tick (K_z bounds, T_min, power limit) are its inputs too: they are read from
the log (a column that varies is an error) and reported in
``ReplayResult.from_log``; the others (Q, K_min and K_max on x and y, F_max,
F_min on x and y, zeta, T_max) come from the parameters.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from vic_drake.control.params import ControllerParams
from vic_drake.control.references import (
    force_references,
    in_contact,
    penetration_rate,
)
from vic_drake.control.stiffness_qp.problem import make_stiffness_qp_problem
from vic_drake.control.stiffness_qp.program import StiffnessQp
from vic_drake.control.tank import tank_step
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import read_bag


@dataclass
class ReplayResult:
    """Per-tick replay of a controller log (ticks = rows 1..n-1).

    Attributes:
        t_s: (m,) tick times.
        stiffness_N_per_m: (m, 3) our K.
        stiffness_logged_N_per_m: (m, 3) the log's K.
        kz_abs_err: (m,) |K_z ours - logged|, N/m.
        tank_abs_err_J: (m,) |T after our tick - logged T|, J.
        success: (m,) bool, the solve succeeded (True on tank-disabled ticks).
        solve_time_s: (m,) solve times.
        solver: solver name.
        r_weight: R used on every axis.
        from_log: the settings read from the log's constant columns (K_z
            bounds, T_min, power limit), which override the parameters.
    """

    t_s: np.ndarray
    stiffness_N_per_m: np.ndarray
    stiffness_logged_N_per_m: np.ndarray
    kz_abs_err: np.ndarray
    tank_abs_err_J: np.ndarray
    success: np.ndarray
    solve_time_s: np.ndarray
    solver: str
    r_weight: float
    from_log: dict

    def summary(self) -> dict:
        """The ``replay-qp`` JSON record."""
        err = self.kz_abs_err
        return {
            "ticks": int(err.size),
            "kz_abs_err_median": float(np.median(err)),
            "kz_abs_err_p99": float(np.percentile(err, 99)),
            "kz_abs_err_max": float(np.max(err)),
            "tank_abs_err_max_J": float(np.max(self.tank_abs_err_J)),
            "solver": self.solver,
            "failures": int(np.count_nonzero(~self.success)),
        }


#: The 31-column log's signals that one replayed tick reads, in order.
REPLAY_COLUMNS = (
    "t_s", "x_m", "y_m", "z_m", "x_d_m", "y_d_m", "z_d_m",
    "vx_m_per_s", "vy_m_per_s", "vz_m_per_s", "force_ref_z_N", "force_min_z_N",
    "tank_energy_J", "stiffness_x_N_per_m", "stiffness_y_N_per_m", "stiffness_z_N_per_m",
)  # fmt: skip


def _logged_constant(df: pd.DataFrame, column: str) -> float:
    """The value of a column the controller logged as a constant setting."""
    logged = df[column].to_numpy(dtype=float)
    value = float(logged[0])
    if not (
        np.all(np.isfinite(logged))
        and np.allclose(logged, value, rtol=1e-9, atol=1e-12)
    ):
        raise VicDrakeError(
            f"log column {column!r} should hold one setting for the whole run; it holds "
            f"{np.unique(logged)[:5].tolist()}... (a replay of a varying setting is not supported)"
        )
    return value


def replay_controller_log(
    df: pd.DataFrame,
    params: ControllerParams | None = None,
    *,
    r_weight: float | None = None,
    solver: str | None = None,
) -> ReplayResult:
    """Replays a 31-column controller log through the QP and the tank.

    Args:
        df: from ``read_bag(path, expect="controller")``.
        params: controller parameters (default: the real controller's).
        r_weight: R on every axis (overrides ``params.qp.r_weight``); > 0.
        solver: "exact", "osqp" or "clarabel" (overrides ``params.qp.solver``).

    Returns:
        ReplayResult; ``summary()`` gives the replay-qp record.

    Raises:
        VicDrakeError: wrong layout, fewer than 2 rows, non-finite inputs, or
            a logged setting (K_z min/max, T_min, power limit) that varies.
    """
    params = ControllerParams() if params is None else params
    qp = params.qp
    if r_weight is not None:
        qp = replace(qp, r_weight=[r_weight] * 3)
    if solver is not None:
        qp = replace(qp, solver=solver)
    qp.validate()
    tank = params.tank.validate()
    if (
        df.attrs.get("layout", "controller") != "controller"
        or "stiffness_z_N_per_m" not in df
    ):
        raise VicDrakeError(
            "replay needs a 31-column controller log (read_bag(path, expect='controller'))"
        )
    if len(df) < 2:
        raise VicDrakeError(f"replay needs at least 2 rows; the log has {len(df)}")
    # Settings the controller logged every tick override the parameters, and
    # are reported in ReplayResult.from_log (so nothing is inferred silently).
    from_log = {
        "stiffness_z_min_N_per_m": _logged_constant(df, "stiffness_z_min_N_per_m"),
        "stiffness_z_max_N_per_m": _logged_constant(df, "stiffness_z_max_N_per_m"),
        "tank_min_J": _logged_constant(df, "tank_min_J"),
        "power_limit_W": _logged_constant(df, "power_limit_W"),
    }
    try:
        k_lo, k_hi = list(qp.stiffness_min_N_per_m), list(qp.stiffness_max_N_per_m)
        k_lo[2] = from_log["stiffness_z_min_N_per_m"]
        k_hi[2] = from_log["stiffness_z_max_N_per_m"]
        qp = replace(qp, stiffness_min_N_per_m=k_lo, stiffness_max_N_per_m=k_hi)
        tank = replace(
            tank,
            min_energy_J=from_log["tank_min_J"],
            power_limit_W=-from_log["power_limit_W"],
        )
    except VicDrakeError as exc:
        raise VicDrakeError(
            f"the log's logged settings are not a valid controller: {exc}"
        ) from exc

    cols = list(REPLAY_COLUMNS)
    data = df[cols].to_numpy(dtype=float)
    if not np.all(np.isfinite(data)):
        bad = [c for c in cols if not np.all(np.isfinite(df[c].to_numpy(dtype=float)))]
        raise VicDrakeError(f"log has non-finite values in columns {bad}")
    rows = data.tolist()  # Plain floats: the QP functions are scalar code.
    solver_obj = StiffnessQp(qp.solver, osqp_eps=qp.osqp_eps)
    k_min = tuple(qp.stiffness_min_N_per_m)
    zeta = qp.damping_ratio
    f_min_xy = (qp.force_min_N[0], qp.force_min_N[1])
    m = len(rows) - 1
    k_out = np.empty((m, 3))
    k_log = np.empty((m, 3))
    tank_err = np.empty(m)
    success = np.ones(m, dtype=bool)
    times = np.zeros(m)
    for j in range(m):
        prev, row = rows[j], rows[j + 1]
        t, x, y, z, xd, yd, zd, vx, vy, vz, f_ref_z, f_min_z, _, kx, ky, kz = row
        dt = t - prev[0]
        energy = prev[12]
        k_prev = prev[13:16]
        damping = tuple(2.0 * zeta * math.sqrt(max(k, 0.0)) for k in k_prev)
        e = (xd - x, yd - y, zd - z)
        e_dot = (-vx, -vy, -vz)
        if energy < tank.min_energy_J:
            k = k_min
        else:
            problem = make_stiffness_qp_problem(
                e, e_dot, damping, (0.0, 0.0, f_ref_z), (*f_min_xy, f_min_z),
                energy, dt, qp, tank,
            )  # fmt: skip
            sol = solver_obj.solve(problem, guess=k_prev)  # The logged previous K.
            k = sol.stiffness
            success[j] = sol.success
            times[j] = sol.solve_time_s
        step = tank_step(energy, e, e_dot, k, k_min, damping, dt, tank)
        k_out[j] = k
        k_log[j] = (kx, ky, kz)
        tank_err[j] = abs(step.energy_J - row[12])
    return ReplayResult(
        t_s=data[1:, 0],
        stiffness_N_per_m=k_out,
        stiffness_logged_N_per_m=k_log,
        kz_abs_err=np.abs(k_out[:, 2] - k_log[:, 2]),
        tank_abs_err_J=tank_err,
        success=success,
        solve_time_s=times,
        solver=qp.solver,
        r_weight=float(qp.r_weight[2]),
        from_log=from_log,
    )


def replay_bag(
    bag_dir: str | os.PathLike,
    params: ControllerParams | None = None,
    *,
    r_weight: float | None = None,
    solver: str | None = None,
) -> ReplayResult:
    """Reads a controller bag and replays it (see :func:`replay_controller_log`)."""
    return replay_controller_log(
        read_bag(bag_dir, expect="controller"), params, r_weight=r_weight, solver=solver
    )


def reference_errors(df: pd.DataFrame, params: ControllerParams | None = None) -> dict:
    """Recomputes the logged F_ref,z and F_min,z with our reference law.

    Uses the logged kappa, lambda, z velocity, surface velocity and sensor
    force; the controller kind is ``params.reference.controller`` ("vs-cf"
    or "vs-vf"). Returns max abs errors (N) and the contact mismatch count.
    """
    params = ControllerParams() if params is None else params
    ref, qp = params.reference, params.qp
    f_ref_err = f_min_err = 0.0
    mismatch = 0
    cols = df[
        [
            "sensor_force_z_N", "kappa_N_per_m_beta", "lambda_N_s_per_m_beta1", "vz_m_per_s",
            "surface_velocity_m_per_s", "force_ref_z_N", "force_min_z_N",
        ]
    ].to_numpy().tolist()  # fmt: skip
    for fz, kappa, lam, vz, sv, f_ref_log, f_min_log in cols:
        contact = in_contact(fz, ref)
        refs = force_references(
            contact=contact, kappa=kappa, lam=lam, eps_dot=penetration_rate(vz, sv),
            beta=1.35, ref=ref, qp=qp,
        )  # fmt: skip
        f_ref_err = max(f_ref_err, abs(refs.force_ref[2] - f_ref_log))
        f_min_err = max(f_min_err, abs(refs.force_min[2] - f_min_log))
        mismatch += contact != (f_ref_log != 0.0)
    return {"force_ref_abs_err_max_N": f_ref_err, "force_min_abs_err_max_N": f_min_err,
            "contact_mismatches": mismatch}  # fmt: skip
