"""The slope fit with the dither as its instrument, in pure Python floats.

Least squares (:mod:`vic_drake.estimation.online.slope_gram`) reads the
slope k from all of the tip's motion beyond the cubic trend. Part of that
motion is the loop's answer to the force: where the surface under the
probe rises faster than the cubic follows, the force rises and the
controller lifts the tip, so the tip's motion is correlated with the part
of the force the fit does not model, and k reads low. The dither is the
controller's own clock, not an answer to the force: its sin and cos
(phase w t, w = 2 pi f_dither, t the controller's time) are instruments for
z0 - z and -z_dot, and the cubic is its own instrument. The fit solves

    sum w zeta (F - phi . theta) = 0,
    zeta = (1, tau, tau^2, tau^3, sin w t, cos w t),
    phi = (1, tau, tau^2, tau^3, z0 - z, -z_dot)

(exactly determined, the instrumental-variable estimate). With the cubic
taken out of every column (its Cholesky factor from
:func:`~vic_drake.estimation.online.slope_gram.cubic_cholesky`), the
unknowns k and c come from a 2 x 2 system.

The fit needs :data:`INSTRUMENT_SIZE` sums beside the least-squares ones:
for u = sin w t, then u = cos w t, sum w u (1, tau, tau^2, tau^3, z0 - z,
-z_dot, F); then sum w sin^2, sum w sin cos, sum w cos^2.
"""

from __future__ import annotations

import math

from vic_drake.estimation.online.slope_gram import cubic_cholesky

#: Number of the instrument's sums.
INSTRUMENT_SIZE = 17
#: The instrument beyond the cubic must keep at least this fraction of its
#: weighted sum of squares (else: no solve).
_INSTRUMENT_REL_TOL = 1e-6


def add_instrument_sample(
    isums, w: float, tau: float, e: float, v: float, force: float, sn: float, cs: float
):
    """The instrument's sums with one more sample (a new list).

    Args:
        isums: the :data:`INSTRUMENT_SIZE` sums.
        w, tau, e, v, force: as
            :func:`~vic_drake.estimation.online.slope_gram.add_sample`.
        sn, cs: sin and cos of the dither's phase at the sample.
    """
    (
        s0, s1, s2, s3, se, sv, sf, c0, c1, c2, c3, ce, cv, cf, ss, sc, cc,
    ) = isums  # fmt: skip
    ws = w * sn
    wc = w * cs
    tau2 = tau * tau
    tau3 = tau2 * tau
    return [
        s0 + ws, s1 + ws * tau, s2 + ws * tau2, s3 + ws * tau3, se + ws * e,
        sv + ws * v, sf + ws * force,
        c0 + wc, c1 + wc * tau, c2 + wc * tau2, c3 + wc * tau3, ce + wc * e,
        cv + wc * v, cf + wc * force,
        ss + ws * sn, sc + ws * cs, cc + wc * cs,
    ]  # fmt: skip


def shift_instruments(isums, d: float, dz: float, scale: float) -> list[float]:
    """The instrument's sums in the basis tau' = tau - d, z0' = z0 + dz,
    times ``scale`` (as
    :func:`~vic_drake.estimation.online.slope_gram.shift_basis`; the
    dither's phase is the controller's time, not tau, and does not move)."""
    s0, s1, s2, s3, se, sv, sf, c0, c1, c2, c3, ce, cv, cf, ss, sc, cc = isums
    p10 = -d
    p20 = p10 * p10
    p30 = p20 * p10
    p21 = 2.0 * p10
    p31 = 3.0 * p20
    p32 = 3.0 * p10
    k = scale
    return [
        k * s0, k * (s1 + p10 * s0), k * (s2 + p21 * s1 + p20 * s0),
        k * (s3 + p32 * s2 + p31 * s1 + p30 * s0), k * (se + dz * s0), k * sv,
        k * sf,
        k * c0, k * (c1 + p10 * c0), k * (c2 + p21 * c1 + p20 * c0),
        k * (c3 + p32 * c2 + p31 * c1 + p30 * c0), k * (ce + dz * c0), k * cv,
        k * cf,
        k * ss, k * sc, k * cc,
    ]  # fmt: skip


def solve_instrumented(sums, isums):
    """The instrumental-variable fit of the force on phi.

    Args:
        sums: the least-squares sums
            (:data:`~vic_drake.estimation.online.slope_gram.SUMS_SIZE`).
        isums: the instrument's sums, on the same basis.

    Returns:
        None where the cubic's block or the 2 x 2 system is singular, or
        the instrument is a cubic's (see below), else (schur_z, k,
        residual, var_factor) as
        :func:`~vic_drake.estimation.online.slope_gram.solve_sums`, with
        residual that of the instrumented fit and var_factor the factor of
        k's variance, sigma^2 var_factor (the instrumental-variable
        sandwich ``M^-1 S M^-T``, M the instruments' cross sums with z0 - z
        and -z_dot, S theirs with each other, all beyond the cubic).
    """
    factor = cubic_cholesky(sums)
    if factor is None:
        return None
    r0, l10, r1, l20, l21, r2, l30, l31, l32, r3 = factor
    (
        _, _, _, _, g04, g05, _, _, _, g14, g15,
        _, _, g24, g25, _, g34, g35, g44, g45, g55,
        b0, b1, b2, b3, b4, b5, ff,
    ) = sums  # fmt: skip
    s0, s1, s2, s3, se, sv, sf, c0, c1, c2, c3, ce, cv, cf, ss, sc, cc = isums
    # Each column's coordinates on the cubic (L^-1 of its cross sums with
    # the cubic, as slope_gram.forward, written out: this runs every solve).
    e0 = g04 * r0
    e1 = (g14 - l10 * e0) * r1
    e2 = (g24 - l20 * e0 - l21 * e1) * r2
    e3 = (g34 - l30 * e0 - l31 * e1 - l32 * e2) * r3
    v0 = g05 * r0
    v1 = (g15 - l10 * v0) * r1
    v2 = (g25 - l20 * v0 - l21 * v1) * r2
    v3 = (g35 - l30 * v0 - l31 * v1 - l32 * v2) * r3
    f0 = b0 * r0
    f1 = (b1 - l10 * f0) * r1
    f2 = (b2 - l20 * f0 - l21 * f1) * r2
    f3 = (b3 - l30 * f0 - l31 * f1 - l32 * f2) * r3
    q0 = s0 * r0
    q1 = (s1 - l10 * q0) * r1
    q2 = (s2 - l20 * q0 - l21 * q1) * r2
    q3 = (s3 - l30 * q0 - l31 * q1 - l32 * q2) * r3
    p0 = c0 * r0
    p1 = (c1 - l10 * p0) * r1
    p2 = (c2 - l20 * p0 - l21 * p1) * r2
    p3 = (c3 - l30 * p0 - l31 * p1 - l32 * p2) * r3
    # Every cross sum below is beyond the cubic (the cubic's part taken out).
    see = g44 - (e0 * e0 + e1 * e1 + e2 * e2 + e3 * e3)
    if not see > 0.0:
        return None
    m_se = se - (q0 * e0 + q1 * e1 + q2 * e2 + q3 * e3)
    m_sv = sv - (q0 * v0 + q1 * v1 + q2 * v2 + q3 * v3)
    m_ce = ce - (p0 * e0 + p1 * e1 + p2 * e2 + p3 * e3)
    m_cv = cv - (p0 * v0 + p1 * v1 + p2 * v2 + p3 * v3)
    det = m_se * m_cv - m_sv * m_ce
    if det == 0.0 or det != det:
        return None
    r_sf = sf - (q0 * f0 + q1 * f1 + q2 * f2 + q3 * f3)
    r_cf = cf - (p0 * f0 + p1 * f1 + p2 * f2 + p3 * f3)
    k = (r_sf * m_cv - m_sv * r_cf) / det
    c = (m_se * r_cf - m_ce * r_sf) / det
    sev = g45 - (e0 * v0 + e1 * v1 + e2 * v2 + e3 * v3)
    svv = g55 - (v0 * v0 + v1 * v1 + v2 * v2 + v3 * v3)
    sef = b4 - (e0 * f0 + e1 * f1 + e2 * f2 + e3 * f3)
    svf = b5 - (v0 * f0 + v1 * f1 + v2 * f2 + v3 * f3)
    sff = ff - (f0 * f0 + f1 * f1 + f2 * f2 + f3 * f3)
    residual = (
        sff - 2.0 * (k * sef + c * svf) + k * k * see + 2.0 * k * c * sev + c * c * svv
    )
    # Over less than a dither period a cubic explains most of sin and cos;
    # what is left of them must stand clear of the sums' rounding.
    z_ss = ss - (q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    z_cc = cc - (p0 * p0 + p1 * p1 + p2 * p2 + p3 * p3)
    if not (z_ss > _INSTRUMENT_REL_TOL * ss and z_cc > _INSTRUMENT_REL_TOL * cc):
        return None
    z_sc = sc - (q0 * p0 + q1 * p1 + q2 * p2 + q3 * p3)
    # k's row of M^-1, and its quadratic form with the instruments' sums.
    a, b = m_cv / det, -m_sv / det
    var_factor = a * a * z_ss + 2.0 * a * b * z_sc + b * b * z_cc
    if not var_factor > 0.0 or var_factor == math.inf:
        return None
    return see, k, residual, var_factor


__all__ = [
    "INSTRUMENT_SIZE",
    "add_instrument_sample",
    "shift_instruments",
    "solve_instrumented",
]
