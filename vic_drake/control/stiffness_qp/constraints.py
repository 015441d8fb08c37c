"""The active-constraint mask of the stiffness QP: one bit per constraint row.

Per axis i (0, 1, 2 = x, y, z) four rows: the stiffness bounds K_min, K_max
and the force rows F_min, F_max, bit ``1 << (4 * i + kind)``; then the two
tank rows (energy, power). :func:`active_constraints` computes the mask of a
given stiffness; the solvers report it in
:class:`~vic_drake.control.stiffness_qp.problem.StiffnessQpSolution`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # Type hint only: problem.py imports nothing from here.
    from vic_drake.control.stiffness_qp.problem import StiffnessQpProblem

AXES = ("x", "y", "z")
KINDS = ("k_min", "k_max", "f_min", "f_max")
#: Bit of the active-constraint mask for (kind, axis): 1 << (4 * axis + kind).
ACTIVE_TANK_ENERGY = 1 << 12
ACTIVE_TANK_POWER = 1 << 13


def active_bit(kind: str, axis: int) -> int:
    """The mask bit of a per-axis constraint kind ('k_min', 'k_max', 'f_min', 'f_max')."""
    return 1 << (4 * axis + KINDS.index(kind))


def active_constraint_names(mask: int) -> list[str]:
    """Names of the constraints in an active mask, e.g. ['k_min_x', 'tank_energy']."""
    names = [
        f"{kind}_{AXES[axis]}"
        for axis in range(3)
        for k, kind in enumerate(KINDS)
        if mask & (1 << (4 * axis + k))
    ]
    if mask & ACTIVE_TANK_ENERGY:
        names.append("tank_energy")
    if mask & ACTIVE_TANK_POWER:
        names.append("tank_power")
    return names


def active_constraints(problem: StiffnessQpProblem, k, *, rtol: float = 1e-6) -> int:
    """Mask of the constraints active at k, within rtol of each row's scale."""
    (e, ed, d, _, fmn, fmx, kmn, kmx, _, _, a, lb_energy, lb_power) = problem
    mask = 0
    bit = 1
    for i in range(3):
        ki = k[i]
        kt = rtol * (kmx[i] if kmx[i] > 1.0 else 1.0)
        if ki - kmn[i] <= kt:
            mask |= bit
        if kmx[i] - ki <= kt:
            mask |= bit << 1
        if e[i] != 0.0:
            f = e[i] * ki + d[i] * ed[i]
            ft = rtol * max(1.0, abs(fmx[i]), abs(fmn[i]))
            if f - fmn[i] <= ft:
                mask |= bit << 2
            if fmx[i] - f <= ft:
                mask |= bit << 3
        bit <<= 4
    ak = a[0] * k[0] + a[1] * k[1] + a[2] * k[2]
    scale = max(abs(a[0]), abs(a[1]), abs(a[2])) * max(kmx)
    if scale > 0.0:
        tt = rtol * max(scale, 1e-12)
        if ak - lb_energy <= tt:  # -inf (no dt) is never active.
            mask |= ACTIVE_TANK_ENERGY
        if ak - lb_power <= tt:
            mask |= ACTIVE_TANK_POWER
    return mask
