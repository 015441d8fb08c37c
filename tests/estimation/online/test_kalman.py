"""The written-out scalar Kalman updates against the loops and the textbook
formula."""

import numpy as np
import pytest

from vic_drake.estimation.online.kalman import scalar_update, scalar_update_loops


def random_problem(rng, n):
    """x, a symmetric positive definite P (flat, exactly symmetric) and h."""
    a = rng.normal(size=(n, n)) * rng.uniform(0.1, 10.0, n)
    P = a @ a.T + 0.1 * np.eye(n)
    P = (P + P.T) / 2.0
    return rng.normal(size=n).tolist(), P.ravel().tolist(), rng.normal(size=n).tolist()


@pytest.mark.parametrize("n", [2, 3, 4])
@pytest.mark.parametrize("gate_sigma", [0.5, 100.0])  # clipped, not clipped
def test_written_out_update_equals_the_loops_to_the_bit(n, gate_sigma):
    rng = np.random.default_rng(n)
    for _ in range(50):
        x, P, h = random_problem(rng, n)
        innovation = float(rng.normal(0.0, 10.0))
        x1, P1, x2, P2 = list(x), list(P), list(x), list(P)
        c1 = scalar_update(x1, P1, h, innovation, 0.04, gate_sigma)
        c2 = scalar_update_loops(x2, P2, h, innovation, 0.04, gate_sigma)
        assert c1 == c2
        assert x1 == x2 and P1 == P2  # bitwise
        assert P1 == np.asarray(P1).reshape(n, n).T.ravel().tolist()  # symmetric


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_update_is_the_kalman_update(n):
    rng = np.random.default_rng(10 + n)
    x, P, h = random_problem(rng, n)
    Pm, hv, r = np.reshape(P, (n, n)), np.asarray(h), 0.3
    s = hv @ Pm @ hv + r
    innovation = 0.5 * np.sqrt(s)  # inside the gate
    k = Pm @ hv / s
    x_new, P_new = list(x), list(P)
    assert not scalar_update(x_new, P_new, h, innovation, r, 4.0)
    np.testing.assert_allclose(x_new, np.asarray(x) + k * innovation, rtol=1e-12)
    np.testing.assert_allclose(
        np.reshape(P_new, (n, n)), Pm - np.outer(k, hv @ Pm), rtol=1e-10, atol=1e-12
    )
    # Beyond the gate: the step is the gate's bound.
    x_clip, P_clip = list(x), list(P)
    assert scalar_update(x_clip, P_clip, h, 100.0 * np.sqrt(s), r, 4.0)
    np.testing.assert_allclose(x_clip, np.asarray(x) + k * 4.0 * np.sqrt(s), rtol=1e-12)
