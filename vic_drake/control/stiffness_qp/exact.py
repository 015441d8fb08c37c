"""The exact solver of the stiffness QP (closed form on its KKT conditions).

The cost is separable, the bound and force rows are per-axis intervals and
both tank rows share the normal a = e * e_dot, so the QP is a separable
strictly convex quadratic on a box with one linear inequality. Its KKT
conditions give k(mu) = clip(k_free + mu a / (2 (Q e^2 + R)), lo, hi), and
a' k(mu) is piecewise linear and nondecreasing in the multiplier mu >= 0;
the exact optimum is found by walking the <= 6 breakpoints. Plain floats, no
numpy, the three axes unrolled: it runs every tick. The test oracle of the
MathematicalProgram (:mod:`vic_drake.control.stiffness_qp.program`) and the
default fast path.
"""

from __future__ import annotations

from time import perf_counter

from vic_drake.control.stiffness_qp.constraints import (
    ACTIVE_TANK_ENERGY,
    ACTIVE_TANK_POWER,
)
from vic_drake.control.stiffness_qp.problem import (
    StiffnessQpProblem,
    StiffnessQpSolution,
    fallback_solution,
)

_INF = float("inf")
#: Tolerance on the per-axis interval and the tank rows (relative, floor 1).
FEASIBILITY_TOL = 1e-9


def solve_stiffness_qp_exact(
    problem: StiffnessQpProblem, *, feas_tol: float = FEASIBILITY_TOL
) -> StiffnessQpSolution:
    """Exact solution of the stiffness QP (closed form on the KKT conditions).

    Args:
        problem: one tick's QP (R > 0 on every axis, so it is strictly convex).
        feas_tol: tolerance on the per-axis interval and tank-row
            feasibility, relative to each row's scale.

    Returns:
        The unique optimum, or K_min with success=False and status
        "infeasible" when the constraints cannot all hold.
    """
    t0 = perf_counter()
    (e, ed, d, fr, fmn, fmx, kmn, kmx, qw, rw, a, lb_energy, lb_power) = problem
    x0 = axis_interval(e[0], ed[0], d[0], fr[0], fmn[0], fmx[0], kmn[0], kmx[0],
                       qw[0], rw[0], 1, feas_tol)  # fmt: skip
    x1 = axis_interval(e[1], ed[1], d[1], fr[1], fmn[1], fmx[1], kmn[1], kmx[1],
                       qw[1], rw[1], 1 << 4, feas_tol)  # fmt: skip
    x2 = axis_interval(e[2], ed[2], d[2], fr[2], fmn[2], fmx[2], kmn[2], kmx[2],
                       qw[2], rw[2], 1 << 8, feas_tol)  # fmt: skip
    if x0 is None or x1 is None or x2 is None:
        return fallback_solution(problem, t0, "infeasible")
    lo0, hi0, lob0, hib0, f0, c0 = x0
    lo1, hi1, lob1, hib1, f1, c1 = x1
    lo2, hi2, lob2, hib2, f2, c2 = x2
    a0, a1, a2 = a

    # mu = 0: clip the free minimiser to the box.
    k0 = lo0 if f0 < lo0 else (hi0 if f0 > hi0 else f0)
    k1 = lo1 if f1 < lo1 else (hi1 if f1 > hi1 else f1)
    k2 = lo2 if f2 < lo2 else (hi2 if f2 > hi2 else f2)
    g = a0 * k0 + a1 * k1 + a2 * k2
    lb = lb_energy if lb_energy > lb_power else lb_power
    mu = 0.0
    if g < lb:
        # The tank row is active. k(mu) = clip(free + mu a / curv, lo, hi) and
        # a' k(mu) is piecewise linear and nondecreasing: walk its breakpoints.
        def at(m: float) -> tuple[float, float, float, float]:
            v0 = f0 + m * a0 / c0
            v1 = f1 + m * a1 / c1
            v2 = f2 + m * a2 / c2
            v0 = lo0 if v0 < lo0 else (hi0 if v0 > hi0 else v0)
            v1 = lo1 if v1 < lo1 else (hi1 if v1 > hi1 else v1)
            v2 = lo2 if v2 < lo2 else (hi2 if v2 > hi2 else v2)
            return v0, v1, v2, 0.0 + a0 * v0 + a1 * v1 + a2 * v2

        best = (
            0.0
            + a0 * (hi0 if a0 > 0.0 else lo0)
            + a1 * (hi1 if a1 > 0.0 else lo1)
            + a2 * (hi2 if a2 > 0.0 else lo2)
        )
        scale = (
            0.0
            + abs(a0) * max(abs(hi0), 1.0)
            + abs(a1) * max(abs(hi1), 1.0)
            + abs(a2) * max(abs(hi2), 1.0)
        )
        if best < lb - feas_tol * max(scale, abs(lb), 1e-12):
            return fallback_solution(problem, t0, "infeasible")
        if best <= lb:
            mu = _INF
            k0 = hi0 if a0 > 0.0 else (lo0 if a0 < 0.0 else k0)
            k1 = hi1 if a1 > 0.0 else (lo1 if a1 < 0.0 else k1)
            k2 = hi2 if a2 > 0.0 else (lo2 if a2 < 0.0 else k2)
        else:
            breaks = []
            for ai, ci, fi, loi, hii in ((a0, c0, f0, lo0, hi0), (a1, c1, f1, lo1, hi1),
                                         (a2, c2, f2, lo2, hi2)):  # fmt: skip
                if ai != 0.0:
                    s = ci / ai
                    m = (loi - fi) * s
                    if m > 0.0:
                        breaks.append(m)
                    m = (hii - fi) * s
                    if m > 0.0:
                        breaks.append(m)
            breaks.sort()
            m_prev, g_prev = 0.0, g
            m_hit = g_hit = None
            for m in breaks:
                g_m = at(m)[3]
                if g_m >= lb:
                    m_hit, g_hit = m, g_m
                    break
                m_prev, g_prev = m, g_m
            if m_hit is None:  # Only reachable by rounding: all variables clipped.
                mu = m_prev
            else:
                mu = m_prev + (lb - g_prev) * (m_hit - m_prev) / (g_hit - g_prev)
            k0, k1, k2, g = at(mu)
    active = 0
    if k0 <= lo0:
        active |= lob0
    if k0 >= hi0:
        active |= hib0
    if k1 <= lo1:
        active |= lob1
    if k1 >= hi1:
        active |= hib1
    if k2 <= lo2:
        active |= lob2
    if k2 >= hi2:
        active |= hib2
    if mu > 0.0:
        if lb_energy >= lb_power:
            active |= ACTIVE_TANK_ENERGY
        if lb_power >= lb_energy:
            active |= ACTIVE_TANK_POWER
    return StiffnessQpSolution(
        (k0, k1, k2), True, active, perf_counter() - t0, "optimal"
    )


def axis_interval(ei, edi, di, fri, fmin, fmax, kmin, kmax, q, r, bit, feas_tol):
    """One axis of the QP: (lo, hi, lo_bit, hi_bit, free, curv), or None if infeasible.

    The bound and force rows make one interval [lo, hi]; lo_bit and hi_bit
    are the mask bits of the rows that set its ends (bit: the axis' K_min
    bit). free is the axis' unconstrained minimiser and curv = 2 (Q e^2 + R)
    the cost's curvature d^2 cost / dk^2. The MathematicalProgram
    (:mod:`~vic_drake.control.stiffness_qp.program`) builds its rows from
    it too, so both solvers call the same ticks infeasible.
    """
    dv = di * edi
    lo, hi = kmin, kmax
    lo_bit, hi_bit = bit, bit << 1
    fmin_i, fmax_i = fmin - dv, fmax - dv
    if ei > 0.0:
        f_lo, f_hi = fmin_i / ei, fmax_i / ei
        if f_lo > lo:
            lo, lo_bit = f_lo, bit << 2
        if f_hi < hi:
            hi, hi_bit = f_hi, bit << 3
    elif ei < 0.0:
        f_lo, f_hi = fmax_i / ei, fmin_i / ei
        if f_lo > lo:
            lo, lo_bit = f_lo, bit << 3
        if f_hi < hi:
            hi, hi_bit = f_hi, bit << 2
    elif fmin_i > feas_tol * max(1.0, abs(fmin)) or fmax_i < -feas_tol * max(
        1.0, abs(fmax)
    ):
        return None
    if lo > hi:
        # hi = -inf: the force row divided by an e that underflows (|e| ~
        # 1e-308); no K of the box reaches it, and inf > inf is False.
        if lo - hi > feas_tol * max(1.0, abs(hi)) or hi == -_INF:
            return None
        hi = lo
    h = q * ei * ei + r
    return lo, hi, lo_bit, hi_bit, (q * ei * (fri - dv) + r * kmin) / h, 2.0 * h
