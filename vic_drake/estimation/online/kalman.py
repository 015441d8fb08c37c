"""The Kalman update with one scalar measurement, on a small covariance.

x is the n-vector of the estimate and P its covariance, row-major in a
flat list of n * n floats, symmetric (every operation on it keeps it
exactly symmetric: the update below, the diagonal prediction, the resets).
The filters have 2 to 4 states; each of these sizes has its update written
out on the upper triangle of P (:func:`scalar_update`), several times
cheaper in pure Python than the loops of :func:`scalar_update_loops`
(every size; the same floating-point operations in the same order, so the
same results to the bit).
"""

from __future__ import annotations

import math


def _gate(innovation: float, s: float, gate_sigma: float) -> tuple[float, bool]:
    """The innovation clipped at ``gate_sigma`` sqrt(s), and whether it was."""
    bound = gate_sigma * math.sqrt(s)
    if abs(innovation) > bound:
        return math.copysign(bound, innovation), True
    return innovation, False


def _update2(x, P, h, innovation, r, gate_sigma):
    h0, h1 = h
    p00, p01, _, p11 = P
    a0 = p00 * h0 + p01 * h1
    a1 = p01 * h0 + p11 * h1
    s = h0 * a0 + h1 * a1 + r
    innovation, clipped = _gate(innovation, s, gate_sigma)
    x[0] += a0 / s * innovation
    x[1] += a1 / s * innovation
    q01 = p01 - a0 * a1 / s
    P[:] = [p00 - a0 * a0 / s, q01, q01, p11 - a1 * a1 / s]
    return clipped


def _update3(x, P, h, innovation, r, gate_sigma):
    h0, h1, h2 = h
    p00, p01, p02, _, p11, p12, _, _, p22 = P
    a0 = p00 * h0 + p01 * h1 + p02 * h2
    a1 = p01 * h0 + p11 * h1 + p12 * h2
    a2 = p02 * h0 + p12 * h1 + p22 * h2
    s = h0 * a0 + h1 * a1 + h2 * a2 + r
    innovation, clipped = _gate(innovation, s, gate_sigma)
    x[0] += a0 / s * innovation
    x[1] += a1 / s * innovation
    x[2] += a2 / s * innovation
    q01, q02 = p01 - a0 * a1 / s, p02 - a0 * a2 / s
    q12 = p12 - a1 * a2 / s
    P[:] = [
        p00 - a0 * a0 / s, q01, q02,
        q01, p11 - a1 * a1 / s, q12,
        q02, q12, p22 - a2 * a2 / s,
    ]  # fmt: skip
    return clipped


def _update4(x, P, h, innovation, r, gate_sigma):
    h0, h1, h2, h3 = h
    p00, p01, p02, p03, _, p11, p12, p13, _, _, p22, p23, _, _, _, p33 = P
    a0 = p00 * h0 + p01 * h1 + p02 * h2 + p03 * h3
    a1 = p01 * h0 + p11 * h1 + p12 * h2 + p13 * h3
    a2 = p02 * h0 + p12 * h1 + p22 * h2 + p23 * h3
    a3 = p03 * h0 + p13 * h1 + p23 * h2 + p33 * h3
    s = h0 * a0 + h1 * a1 + h2 * a2 + h3 * a3 + r
    innovation, clipped = _gate(innovation, s, gate_sigma)
    x[0] += a0 / s * innovation
    x[1] += a1 / s * innovation
    x[2] += a2 / s * innovation
    x[3] += a3 / s * innovation
    q01, q02, q03 = p01 - a0 * a1 / s, p02 - a0 * a2 / s, p03 - a0 * a3 / s
    q12, q13 = p12 - a1 * a2 / s, p13 - a1 * a3 / s
    q23 = p23 - a2 * a3 / s
    P[:] = [
        p00 - a0 * a0 / s, q01, q02, q03,
        q01, p11 - a1 * a1 / s, q12, q13,
        q02, q12, p22 - a2 * a2 / s, q23,
        q03, q13, q23, p33 - a3 * a3 / s,
    ]  # fmt: skip
    return clipped


_WRITTEN_OUT = {2: _update2, 3: _update3, 4: _update4}


def scalar_update(
    x: list[float],
    P: list[float],
    h: list[float],
    innovation: float,
    r: float,
    gate_sigma: float,
) -> bool:
    """Kalman update with one scalar measurement, in place; True if clipped.

    The measurement is h . x with noise variance r. The innovation is
    clipped at ``gate_sigma`` predicted standard deviations (Huber-like):
    a spike moves x by a bounded step. P must be symmetric.
    """
    update = _WRITTEN_OUT.get(len(x), scalar_update_loops)
    return update(x, P, h, innovation, r, gate_sigma)


def scalar_update_loops(
    x: list[float],
    P: list[float],
    h: list[float],
    innovation: float,
    r: float,
    gate_sigma: float,
) -> bool:
    """:func:`scalar_update` for any n, by loops over P."""
    n = len(x)
    # Left-to-right sums, as written out above: ``sum()`` of floats is
    # compensated from Python 3.12 on and would give other bits there.
    Ph = []
    for i in range(n):
        acc = P[i * n] * h[0]
        for j in range(1, n):
            acc += P[i * n + j] * h[j]
        Ph.append(acc)
    s = h[0] * Ph[0]
    for i in range(1, n):
        s += h[i] * Ph[i]
    s += r
    innovation, clipped = _gate(innovation, s, gate_sigma)
    for i in range(n):
        x[i] += Ph[i] / s * innovation
    for i in range(n):
        for j in range(n):
            P[i * n + j] -= Ph[i] * Ph[j] / s
    return clipped


__all__ = ["scalar_update", "scalar_update_loops"]
