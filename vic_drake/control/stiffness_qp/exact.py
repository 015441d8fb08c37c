"""The exact solver of the stiffness QP (closed form on its KKT conditions).

The cost is separable, the bound and force rows are per-axis intervals and
both tank rows share the normal a = e * e_dot, so the QP is a separable
strictly convex quadratic on a box with one linear inequality. Its KKT
conditions give k(mu) = clip(k_free + mu a / (2 (Q e^2 + R)), lo, hi), and
a' k(mu) is piecewise linear and nondecreasing in the multiplier mu >= 0;
the exact optimum is found by walking the <= 6 breakpoints. Plain floats, no
numpy: it runs every tick. The test oracle of the MathematicalProgram
(:mod:`vic_drake.control.stiffness_qp.program`) and the default fast path.
"""

from __future__ import annotations

import math
import time

from vic_drake.control.stiffness_qp.constraints import (
    ACTIVE_TANK_ENERGY,
    ACTIVE_TANK_POWER,
)
from vic_drake.control.stiffness_qp.problem import (
    StiffnessQpProblem,
    StiffnessQpSolution,
    fallback_solution,
)


def solve_stiffness_qp_exact(
    problem: StiffnessQpProblem, *, feas_tol: float = 1e-9
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
    t0 = time.perf_counter()
    (e, ed, d, fr, fmn, fmx, kmn, kmx, qw, rw, a, lb_energy, lb_power) = problem
    lo = []
    hi = []
    lo_bit = []
    hi_bit = []
    free = []
    curv = []  # 2 (Q e^2 + R): d^2 cost / dk^2.
    bit = 1
    # Per axis: the bound and force rows make one interval [lo, hi]; the
    # unconstrained minimiser is `free`.
    for ei, edi, di, fri, fmin, fmax, kmin, kmax, q, r in zip(
        e, ed, d, fr, fmn, fmx, kmn, kmx, qw, rw
    ):
        dv = di * edi
        lo_i, hi_i = kmin, kmax
        lb_i, hb_i = bit, bit << 1
        fmin_i, fmax_i = fmin - dv, fmax - dv
        if ei > 0.0:
            f_lo, f_hi = fmin_i / ei, fmax_i / ei
            if f_lo > lo_i:
                lo_i, lb_i = f_lo, bit << 2
            if f_hi < hi_i:
                hi_i, hb_i = f_hi, bit << 3
        elif ei < 0.0:
            f_lo, f_hi = fmax_i / ei, fmin_i / ei
            if f_lo > lo_i:
                lo_i, lb_i = f_lo, bit << 3
            if f_hi < hi_i:
                hi_i, hb_i = f_hi, bit << 2
        elif fmin_i > feas_tol * max(1.0, abs(fmin)) or fmax_i < -feas_tol * max(
            1.0, abs(fmax)
        ):
            return fallback_solution(problem, t0, "infeasible")
        if lo_i > hi_i:
            if lo_i - hi_i > feas_tol * max(1.0, abs(hi_i)):
                return fallback_solution(problem, t0, "infeasible")
            hi_i = lo_i
        lo.append(lo_i)
        hi.append(hi_i)
        lo_bit.append(lb_i)
        hi_bit.append(hb_i)
        h = q * ei * ei + r
        curv.append(2.0 * h)
        free.append((q * ei * (fri - dv) + r * kmin) / h)
        bit <<= 4

    # mu = 0: clip the free minimiser to the box.
    k = [
        lo_i if v < lo_i else (hi_i if v > hi_i else v)
        for v, lo_i, hi_i in zip(free, lo, hi)
    ]
    g = a[0] * k[0] + a[1] * k[1] + a[2] * k[2]
    lb = lb_energy if lb_energy > lb_power else lb_power
    mu = 0.0
    if g < lb:
        # The tank row is active. k(mu) = clip(free + mu a / curv, lo, hi) and
        # a' k(mu) is piecewise linear and nondecreasing: walk its breakpoints.
        def at(mu_: float) -> tuple[list[float], float]:
            k_ = [0.0, 0.0, 0.0]
            g_ = 0.0
            for i in range(3):
                v = free[i] + mu_ * a[i] / curv[i]
                k_[i] = lo[i] if v < lo[i] else (hi[i] if v > hi[i] else v)
                g_ += a[i] * k_[i]
            return k_, g_

        best = 0.0
        scale = 0.0
        for i in range(3):
            best += a[i] * (hi[i] if a[i] > 0.0 else lo[i])
            scale += abs(a[i]) * max(abs(hi[i]), 1.0)
        if best < lb - feas_tol * max(scale, abs(lb), 1e-12):
            return fallback_solution(problem, t0, "infeasible")
        if best <= lb:
            mu = math.inf
            k = [
                hi[i] if a[i] > 0.0 else (lo[i] if a[i] < 0.0 else k[i])
                for i in range(3)
            ]
        else:
            breaks = []
            for i in range(3):
                if a[i] != 0.0:
                    s = curv[i] / a[i]
                    for bound in (lo[i], hi[i]):
                        m = (bound - free[i]) * s
                        if m > 0.0:
                            breaks.append(m)
            breaks.sort()
            m_prev, g_prev = 0.0, g
            m_hit = g_hit = None
            for m in breaks:
                _, g_m = at(m)
                if g_m >= lb:
                    m_hit, g_hit = m, g_m
                    break
                m_prev, g_prev = m, g_m
            if m_hit is None:  # Only reachable by rounding: all variables clipped.
                mu = m_prev
            else:
                mu = m_prev + (lb - g_prev) * (m_hit - m_prev) / (g_hit - g_prev)
            k, g = at(mu)
    active = 0
    for i in range(3):
        if k[i] <= lo[i]:
            active |= lo_bit[i]
        if k[i] >= hi[i]:
            active |= hi_bit[i]
    if mu > 0.0:
        active |= ACTIVE_TANK_ENERGY if lb_energy >= lb_power else 0
        active |= ACTIVE_TANK_POWER if lb_power >= lb_energy else 0
    return StiffnessQpSolution(
        (k[0], k[1], k[2]), True, active, time.perf_counter() - t0, "optimal"
    )
