"""The slope fit's weighted normal equations, in pure Python floats.

The fit of :mod:`vic_drake.estimation.online.slope` regresses the force on
the six functions

    phi = (1, tau, tau^2, tau^3, z0 - z, -z_dot)

with weights w. Its sufficient statistics are 28 floats, in this order
(:data:`SUMS_SIZE`): the upper triangle of the Gram matrix G = sum w phi
phi^T row by row (G00, G01, ..., G05, G11, ..., G55), the right-hand side
b = sum w F phi, and sum w F^2. Three functions work on them:

- :func:`add_sample` adds one sample;
- :func:`shift_basis` moves the time origin by d and z0 by dz and scales
  every sum (the exponential forgetting of the time elapsed);
- :func:`solve_sums` solves the normal equations by a Cholesky
  factorisation G = L L^T, from which everything the fit reports follows
  without a second solve.

Everything is written out term by term: at six unknowns numpy's cost per
call (about 1-3 us for each small array operation) would dominate.
"""

from __future__ import annotations

import math

#: Number of sums of the Gram matrix's upper triangle (the first sums).
GRAM_SIZE = 21
#: Number of sums: the Gram upper triangle, the 6 of the right-hand side, and 1.
SUMS_SIZE = GRAM_SIZE + 6 + 1


def add_sample(sums, w: float, tau: float, e: float, v: float, force: float):
    """The sums with one more sample of weight w (a new list).

    Args:
        sums: the :data:`SUMS_SIZE` sums.
        w: the sample's weight.
        tau, e, v: its tau, z0 - z and -z_dot.
        force: its force, N.
    """
    (
        g00, g01, g02, g03, g04, g05, g11, g12, g13, g14, g15,
        g22, g23, g24, g25, g33, g34, g35, g44, g45, g55,
        b0, b1, b2, b3, b4, b5, ff,
    ) = sums  # fmt: skip
    tau2 = tau * tau
    tau3 = tau2 * tau
    w1, w2, w3, w4 = w * tau, w * tau2, w * tau3, w * e
    wf = w * force
    return [
        g00 + w, g01 + w1, g02 + w2, g03 + w3, g04 + w4, g05 + w * v,
        g11 + w1 * tau, g12 + w1 * tau2, g13 + w1 * tau3, g14 + w1 * e,
        g15 + w1 * v, g22 + w2 * tau2, g23 + w2 * tau3, g24 + w2 * e,
        g25 + w2 * v, g33 + w3 * tau3, g34 + w3 * e, g35 + w3 * v,
        g44 + w4 * e, g45 + w4 * v, g55 + w * v * v,
        b0 + wf, b1 + wf * tau, b2 + wf * tau2, b3 + wf * tau3, b4 + wf * e,
        b5 + wf * v, ff + wf * force,
    ]  # fmt: skip


def shift_basis(sums, d: float, dz: float, scale: float) -> list[float]:
    """The sums in the basis tau' = tau - d, z0' = z0 + dz, times ``scale``.

    phi' = A phi with A lower triangular and a unit diagonal:
    (tau - d)^i = sum_j C(i, j) (-d)^(i - j) tau^j and z0' - z = z0 - z +
    dz; G' = scale A G A^T, b' = scale A b, sum w F^2 scaled.
    """
    (
        g00, g01, g02, g03, g04, g05, g11, g12, g13, g14, g15,
        g22, g23, g24, g25, g33, g34, g35, g44, g45, g55,
        b0, b1, b2, b3, b4, b5, ff,
    ) = sums  # fmt: skip
    # The cubic's block of A: rows (1), (p10 1), (p20 p21 1), (p30 p31 p32 1).
    p10 = -d
    p20 = p10 * p10
    p30 = p20 * p10
    p21 = 2.0 * p10
    p31 = 3.0 * p20
    p32 = 3.0 * p10
    # M = A T (T the cubic's 4 x 4 block; its rows are its columns).
    m10 = g01 + p10 * g00
    m11 = g11 + p10 * g01
    m12 = g12 + p10 * g02
    m13 = g13 + p10 * g03
    m20 = g02 + p21 * g01 + p20 * g00
    m21 = g12 + p21 * g11 + p20 * g01
    m22 = g22 + p21 * g12 + p20 * g02
    m23 = g23 + p21 * g13 + p20 * g03
    m30 = g03 + p32 * g02 + p31 * g01 + p30 * g00
    m31 = g13 + p32 * g12 + p31 * g11 + p30 * g01
    m32 = g23 + p32 * g22 + p31 * g12 + p30 * g02
    m33 = g33 + p32 * g23 + p31 * g13 + p30 * g03
    # The z column: (z0' - z) = (z0 - z) + dz * 1.
    u0 = g04 + dz * g00
    u1 = g14 + dz * g01
    u2 = g24 + dz * g02
    u3 = g34 + dz * g03
    s = scale
    return [
        # Row 0 of A T A^T = (M A^T) row 0.
        s * g00,
        s * (g01 + p10 * g00),
        s * (g02 + p21 * g01 + p20 * g00),
        s * (g03 + p32 * g02 + p31 * g01 + p30 * g00),
        s * u0,
        s * g05,
        s * (m11 + p10 * m10),
        s * (m12 + p21 * m11 + p20 * m10),
        s * (m13 + p32 * m12 + p31 * m11 + p30 * m10),
        s * (u1 + p10 * u0),
        s * (g15 + p10 * g05),
        s * (m22 + p21 * m21 + p20 * m20),
        s * (m23 + p32 * m22 + p31 * m21 + p30 * m20),
        s * (u2 + p21 * u1 + p20 * u0),
        s * (g25 + p21 * g15 + p20 * g05),
        s * (m33 + p32 * m32 + p31 * m31 + p30 * m30),
        s * (u3 + p32 * u2 + p31 * u1 + p30 * u0),
        s * (g35 + p32 * g25 + p31 * g15 + p30 * g05),
        s * (g44 + dz * (2.0 * g04 + dz * g00)),
        s * (g45 + dz * g05),
        s * g55,
        s * b0,
        s * (b1 + p10 * b0),
        s * (b2 + p21 * b1 + p20 * b0),
        s * (b3 + p32 * b2 + p31 * b1 + p30 * b0),
        s * (b4 + dz * b0),
        s * b5,
        s * ff,
    ]


def cubic_cholesky(sums):
    """The Cholesky factor of the cubic's 4 x 4 block of G (the first rows
    of :func:`solve_sums`'s L), as (r0, l10, r1, l20, l21, r2, l30, l31,
    l32, r3) with ri = 1 / Lii; None where the block is not numerically
    positive definite."""
    g00, g01, g02, g03, _, _, g11, g12, g13, _, _, g22, g23, _, _, g33 = sums[:16]
    if not g00 > 0.0:
        return None
    r0 = 1.0 / math.sqrt(g00)
    l10, l20, l30 = g01 * r0, g02 * r0, g03 * r0
    p = g11 - l10 * l10
    if not p > 0.0:
        return None
    r1 = 1.0 / math.sqrt(p)
    l21 = (g12 - l20 * l10) * r1
    l31 = (g13 - l30 * l10) * r1
    p = g22 - l20 * l20 - l21 * l21
    if not p > 0.0:
        return None
    r2 = 1.0 / math.sqrt(p)
    l32 = (g23 - l30 * l20 - l31 * l21) * r2
    p = g33 - l30 * l30 - l31 * l31 - l32 * l32
    if not p > 0.0:
        return None
    return r0, l10, r1, l20, l21, r2, l30, l31, l32, 1.0 / math.sqrt(p)


def solve_sums(sums):
    """The weighted least-squares fit of the force on phi, by Cholesky.

    Returns:
        None if G is not numerically positive definite (a pivot <= 0 or
        not finite), else (schur_z, coef_z, residual, g_inv_zz):

        - schur_z: the weighted sum of squares of z0 - z beyond what the
          cubic explains (the Schur complement of the cubic in the z, z
          entry, = L44^2);
        - coef_z: the coefficient of z0 - z (the slope k);
        - residual: sum w F^2 - coef . b, the weighted sum of squared
          residuals (not clipped at 0);
        - g_inv_zz: the z, z entry of G^-1.
    """
    (
        g00, g01, g02, g03, g04, g05, g11, g12, g13, g14, g15,
        g22, g23, g24, g25, g33, g34, g35, g44, g45, g55,
        b0, b1, b2, b3, b4, b5, ff,
    ) = sums  # fmt: skip
    factor = cubic_cholesky(sums)
    if factor is None:
        return None
    r0, l10, r1, l20, l21, r2, l30, l31, l32, r3 = factor
    l40 = g04 * r0
    l41 = (g14 - l40 * l10) * r1
    l42 = (g24 - l40 * l20 - l41 * l21) * r2
    l43 = (g34 - l40 * l30 - l41 * l31 - l42 * l32) * r3
    l50 = g05 * r0
    l51 = (g15 - l50 * l10) * r1
    l52 = (g25 - l50 * l20 - l51 * l21) * r2
    l53 = (g35 - l50 * l30 - l51 * l31 - l52 * l32) * r3
    schur_z = g44 - l40 * l40 - l41 * l41 - l42 * l42 - l43 * l43
    if not schur_z > 0.0:
        return None
    r4 = 1.0 / math.sqrt(schur_z)
    l54 = (g45 - l50 * l40 - l51 * l41 - l52 * l42 - l53 * l43) * r4
    p = g55 - l50 * l50 - l51 * l51 - l52 * l52 - l53 * l53 - l54 * l54
    if not p > 0.0:
        return None
    r5 = 1.0 / math.sqrt(p)
    # y = L^-1 b; coef = L^-T y, of which only the last two are needed.
    y0 = b0 * r0
    y1 = (b1 - l10 * y0) * r1
    y2 = (b2 - l20 * y0 - l21 * y1) * r2
    y3 = (b3 - l30 * y0 - l31 * y1 - l32 * y2) * r3
    y4 = (b4 - l40 * y0 - l41 * y1 - l42 * y2 - l43 * y3) * r4
    y5 = (b5 - l50 * y0 - l51 * y1 - l52 * y2 - l53 * y3 - l54 * y4) * r5
    coef_z = (y4 - l54 * y5 * r5) * r4
    # coef . b = y . y; (G^-1)_zz = |L^-1 e_z|^2 = r4^2 (1 + (l54 r5)^2).
    residual = ff - (y0 * y0 + y1 * y1 + y2 * y2 + y3 * y3 + y4 * y4 + y5 * y5)
    q = l54 * r5
    g_inv_zz = r4 * r4 * (1.0 + q * q)
    return schur_z, coef_z, residual, g_inv_zz


__all__ = [
    "GRAM_SIZE",
    "SUMS_SIZE",
    "add_sample",
    "cubic_cholesky",
    "shift_basis",
    "solve_sums",
]
